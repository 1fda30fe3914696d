//! The one policy type: a [`LinearArms`] estimator scored with the LinUCB
//! bonus, plus a [`QueryRule`] that decides whether to act or to ask.
//!
//! Every paper policy is this type with a different rule (the MABWiser
//! pattern: one learner, a thin decision rule per policy), so naming,
//! learning and checkpointing are written once here.

use std::fmt::Debug;

use hil_core::{
    ArmDiagnostics, ArmId, Decision, DecisionInput, Diagnostics, Feedback, Policy, Result,
};
use serde_json::Value;

use crate::common;
use crate::estimator::{ArmEstimate, LinearArms};

/// What a rule sees when it decides (one struct, so that adding a field
/// never breaks a rule).
#[derive(Debug)]
pub struct RuleContext<'a, 'b> {
    /// Every arm's score at the decision's context, indexed by arm.
    pub scores: &'a [ArmEstimate],
    /// The LinUCB arm argmax θᵀx + α·b(x): what the policy acts with, and
    /// the fallback of a query.
    pub ucb_arm: ArmId,
    /// The session's decision input (attempt, items seen, workload forecast).
    pub input: &'a DecisionInput<'b>,
    /// The decision's diagnostics, already holding the per-arm figures; the
    /// rule may add to them and the policy attaches them to its decision.
    pub diagnostics: &'a mut Diagnostics,
}

/// How a policy turns scored arms into a decision: act with the LinUCB
/// arm, or ask. A rule *is* its validated hyperparameters (α included);
/// randomness or counters it needs live in its [`QueryRule::State`].
/// Implement it (and [`crate::RuleConfig`] for configs) to add a policy over
/// the shared estimator.
pub trait QueryRule: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// The policy's name: in checkpoints, records and configs (`type`).
    const NAME: &'static str;
    /// The rule's mutable state (`()` for none); its `Default` is the state
    /// before [`hil_core::Policy::seed`] is called.
    type State: Clone + Debug + Default + Send;

    /// The weight α ≥ 0 of the confidence bonus.
    fn alpha(&self) -> f64;
    /// Decides from `ctx`.
    fn decide(&self, state: &mut Self::State, ctx: RuleContext<'_, '_>) -> Result<Decision>;
    /// Reseeds the state's randomness, if it has any.
    fn seed(_state: &mut Self::State, _seed: u64) {}
    /// The state for checkpoints (`null` if there is none).
    fn save_state(_state: &Self::State) -> Value {
        Value::Null
    }
    /// Restores [`QueryRule::save_state`]; on error nothing changes.
    fn restore_state(_state: &mut Self::State, _saved: Value) -> Result<()> {
        Ok(())
    }
}

/// A policy over the shared linear-arm estimator, deciding with rule `R`.
/// [`crate::LinUcb`], [`crate::AlwaysQuery`], [`crate::LinUcbExpDecay`] and
/// [`crate::LinUcbQg`] are this type with their rules.
///
/// Checkpoints hold the policy name, the estimator and the rule's state;
/// `restore` accepts only a checkpoint of the same policy and shape.
#[derive(Clone, Debug)]
pub struct LinearPolicy<R: QueryRule> {
    rule: R,
    state: R::State,
    arms: LinearArms,
}

impl<R: QueryRule> LinearPolicy<R> {
    /// The policy with rule (hyperparameters) `rule` over `arms` (possibly
    /// pretrained).
    pub fn new(rule: R, arms: LinearArms) -> Self {
        Self {
            rule,
            state: R::State::default(),
            arms,
        }
    }

    /// The parameters.
    pub fn params(&self) -> R {
        self.rule
    }

    /// The estimator.
    pub fn estimator(&self) -> &LinearArms {
        &self.arms
    }
}

impl<R: QueryRule> Policy for LinearPolicy<R> {
    fn name(&self) -> &str {
        R::NAME
    }
    fn n_arms(&self) -> usize {
        self.arms.n_arms()
    }
    fn dim(&self) -> usize {
        self.arms.dim()
    }
    fn seed(&mut self, seed: u64) {
        R::seed(&mut self.state, seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let alpha = self.rule.alpha();
        // The estimator validates the context (dimension, finiteness).
        let scores = self.arms.scores(input.context)?;
        let mut diag = Diagnostics::new().with_arms(
            scores
                .iter()
                .map(|e| ArmDiagnostics::new(e.estimate, e.bonus, e.ucb(alpha)))
                .collect(),
        );
        let ucb_arm = ArmId(common::argmax(&scores, |s| s.ucb(alpha)));
        let ctx = RuleContext {
            scores: &scores,
            ucb_arm,
            input,
            diagnostics: &mut diag,
        };
        let d = self.rule.decide(&mut self.state, ctx)?;
        Ok(d.with_diagnostics(diag))
    }
    /// Learns from the executed arm and its reward (the expert's arm after
    /// a query, too); the estimator validates context, arm and reward.
    fn observe(&mut self, fb: &Feedback<'_>) -> Result<()> {
        self.arms.update(fb.context, fb.arm, fb.reward)
    }
    fn save(&self) -> Result<Value> {
        Ok(common::save(
            R::NAME,
            &self.arms,
            R::save_state(&self.state),
        ))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let (arms, extra) = common::restore(self, state)?;
        // The rule first: if its state is bad, nothing has changed.
        R::restore_state(&mut self.state, extra)?;
        self.arms = arms;
        Ok(())
    }
}
