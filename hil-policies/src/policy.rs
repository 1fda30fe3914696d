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

/// How a policy turns scored arms into a decision: act with the LinUCB
/// arm, or ask. Implement it (and [`crate::RuleConfig`] for configs) to add
/// a policy over the shared estimator.
pub trait QueryRule: Clone + Debug + Send + 'static {
    /// The policy's name: in checkpoints, records and configs (`type`).
    const NAME: &'static str;
    /// Validated hyperparameters (α included).
    type Params: Copy + Debug + PartialEq;

    /// The rule with these parameters (and any state at its initial value).
    fn from_params(params: Self::Params) -> Self;
    /// The parameters it was made with.
    fn params(&self) -> Self::Params;
    /// The weight α ≥ 0 of the confidence bonus.
    fn alpha(&self) -> f64;
    /// Decides at `input` given every arm's score (`scores`, indexed by
    /// arm) and the LinUCB arm argmax θᵀx + α·b(x) (`ucb_arm`, also the
    /// fallback of a query). May add to `diag`, which already holds the
    /// per-arm figures; the policy attaches it to the returned decision.
    fn decide(
        &mut self,
        scores: &[ArmEstimate],
        ucb_arm: ArmId,
        input: &DecisionInput<'_>,
        diag: &mut Diagnostics,
    ) -> Result<Decision>;
    /// Reseeds the rule's randomness, if it has any.
    fn seed(&mut self, _seed: u64) {}
    /// The rule's own state for checkpoints (`null` if it has none).
    fn save_state(&self) -> Value {
        Value::Null
    }
    /// Restores [`QueryRule::save_state`]; on error the rule is unchanged.
    fn restore_state(&mut self, _state: Value) -> Result<()> {
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
    arms: LinearArms,
}

impl<R: QueryRule> LinearPolicy<R> {
    /// The policy over `arms` (possibly pretrained).
    pub fn new(params: R::Params, arms: LinearArms) -> Self {
        Self {
            rule: R::from_params(params),
            arms,
        }
    }

    /// The parameters.
    pub fn params(&self) -> R::Params {
        self.rule.params()
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
        self.rule.seed(seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let alpha = self.rule.alpha();
        // The estimator validates the context (dimension, finiteness).
        let scores = self.arms.scores(input.context)?;
        let mut diag = Diagnostics {
            arms: scores
                .iter()
                .map(|e| ArmDiagnostics {
                    estimate: e.estimate,
                    bonus: e.bonus,
                    ucb: e.ucb(alpha),
                })
                .collect(),
            ..Default::default()
        };
        let ucb_arm = ArmId(common::argmax(&scores, |s| s.ucb(alpha)));
        let d = self.rule.decide(&scores, ucb_arm, input, &mut diag)?;
        Ok(d.with_diagnostics(diag))
    }
    /// Learns from the executed arm and its reward (the expert's arm after
    /// a query, too); the estimator validates context, arm and reward.
    fn observe(&mut self, fb: &Feedback<'_>) -> Result<()> {
        self.arms.update(fb.context, fb.arm, fb.reward)
    }
    fn save(&self) -> Result<Value> {
        Ok(common::save(R::NAME, &self.arms, self.rule.save_state()))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let (arms, extra) = common::restore(self, state)?;
        // The rule first: if its state is bad, nothing has changed.
        self.rule.restore_state(extra)?;
        self.arms = arms;
        Ok(())
    }
}
