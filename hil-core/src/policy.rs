//! The [`Policy`] trait: decide to act or ask, and learn from outcomes.

use serde_json::Value;

use crate::action::ArmId;
use crate::context::Context;
use crate::decision::Decision;
use crate::error::{HilError, Result};
use crate::time::Timestep;
use crate::workload::WorkloadForecast;

/// What a policy knows when it decides.
///
/// ```
/// use hil_core::{Context, DecisionInput, QueryHistory, WorkloadForecast};
/// let x = Context::new(vec![0.5; 3]).unwrap();
/// let h = QueryHistory::new();
/// let input = DecisionInput::new(&x, 4, WorkloadForecast::none(&h)).at_item(1, 1, 2);
/// assert_eq!((input.t, input.item_index, input.items_seen, input.attempt), (4, 1, 1, 2));
/// ```
#[derive(Debug)]
#[non_exhaustive]
pub struct DecisionInput<'a> {
    /// The context of the current observation.
    pub context: &'a Context,
    /// Session timestep (1-based).
    pub t: Timestep,
    /// Index of the current item in the episode (0-based).
    pub item_index: usize,
    /// Number of items seen before the current one (N in LinUCB-ExpDecay).
    pub items_seen: usize,
    /// Attempt number at the current item (0 = first timestep of this item).
    pub attempt: u32,
    /// Forecasts of the querying workload, for policies that weigh it.
    pub workload: WorkloadForecast<'a>,
}

impl<'a> DecisionInput<'a> {
    /// The input at timestep `t` for `context`, at the first attempt at the
    /// first item of an episode ([`DecisionInput::at_item`] moves it).
    pub fn new(context: &'a Context, t: Timestep, workload: WorkloadForecast<'a>) -> Self {
        Self {
            context,
            t,
            item_index: 0,
            items_seen: 0,
            attempt: 0,
            workload,
        }
    }

    /// At attempt `attempt` (0-based) of item `item_index` (0-based), after
    /// `items_seen` earlier items.
    pub fn at_item(mut self, item_index: usize, items_seen: usize, attempt: u32) -> Self {
        self.item_index = item_index;
        self.items_seen = items_seen;
        self.attempt = attempt;
        self
    }
}

/// The facts of one attempt, by name: what [`Feedback::new`] takes, so the
/// call site says which number is the reward and which the timestep.
#[derive(Clone, Copy, Debug)]
pub struct Attempt<'a> {
    /// The context the attempt was made in.
    pub context: &'a Context,
    /// The arm that was executed (the expert's after a query).
    pub arm: ArmId,
    /// The observed reward (1 on success, 0 otherwise).
    pub reward: f64,
    /// Session timestep of the attempt.
    pub t: Timestep,
}

/// What a policy learns from after an attempt.
///
/// ```
/// use hil_core::{ArmId, Attempt, Context, Feedback};
/// let x = Context::new(vec![0.5; 3]).unwrap();
/// let f = Feedback::new(Attempt { context: &x, arm: ArmId(2), reward: 1.0, t: 4 })
///     .from_expert(true);
/// assert!(f.from_expert && f.reward == 1.0 && f.t == 4);
/// ```
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct Feedback<'a> {
    /// The context the attempt was made in.
    pub context: &'a Context,
    /// The arm that was executed (the expert's after a query).
    pub arm: ArmId,
    /// The observed reward (1 on success, 0 otherwise).
    pub reward: f64,
    /// Session timestep of the attempt.
    pub t: Timestep,
    /// Whether the arm came from a human answer rather than the policy.
    pub from_expert: bool,
}

impl<'a> Feedback<'a> {
    /// The feedback of `attempt`, whose arm the policy chose (see
    /// [`Feedback::from_expert`]).
    pub fn new(attempt: Attempt<'a>) -> Self {
        let Attempt {
            context,
            arm,
            reward,
            t,
        } = attempt;
        Self {
            context,
            arm,
            reward,
            t,
            from_expert: false,
        }
    }

    /// Marks whether the arm came from a human answer.
    pub fn from_expert(mut self, from_expert: bool) -> Self {
        self.from_expert = from_expert;
        self
    }
}

/// A contextual-bandit policy with a query action.
///
/// Object-safe, no generics or associated types, so it can be named in
/// configs through typetag and cross a plugin boundary.
///
/// Contract (checked by `hil_conformance::check_policy`):
/// - `decide` returns an arm in `0..n_arms()` (as `Act` or as a query's
///   `fallback`) and errors on a context of the wrong dimension;
/// - given the same seed and inputs, a policy makes the same decisions;
/// - `restore(save())` gives a policy that continues identically.
///
/// The session loop calls `decide` only for attempts the policy owns: after a
/// query, later attempts at the same item execute the expert's arm and the
/// policy is only told about them through `observe`.
pub trait Policy: Send {
    /// Short name for logs (e.g. `linucb_qg`).
    fn name(&self) -> &str;

    /// Number of robot actions the policy chooses among.
    fn n_arms(&self) -> usize;

    /// Context dimension the policy expects.
    fn dim(&self) -> usize;

    /// Reseeds the policy's own randomness. Deterministic policies ignore it.
    fn seed(&mut self, seed: u64) {
        let _ = seed;
    }

    /// Decides what to do for the current observation.
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision>;

    /// Learns from the outcome of an executed attempt.
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()>;

    /// Serialises the full learning state (estimates, RNG state, counters).
    /// A policy that cannot checkpoint keeps this default, which returns
    /// [`HilError::Unsupported`] (the conformance suite then skips its
    /// checkpoint check).
    fn save(&self) -> Result<Value> {
        Err(HilError::unsupported(
            self.name(),
            "checkpoints",
            "this policy does not implement save()",
        ))
    }

    /// Restores a state produced by [`Policy::save`] on a policy of the same type.
    fn restore(&mut self, state: Value) -> Result<()> {
        let _ = state;
        Err(HilError::unsupported(
            self.name(),
            "checkpoints",
            "this policy does not implement restore()",
        ))
    }
}

/// Checks the parts of a [`DecisionInput`] every policy must validate.
pub fn check_input(policy: &dyn Policy, input: &DecisionInput<'_>) -> Result<()> {
    input.context.check_dim(policy.dim())
}

/// Checks the parts of a [`Feedback`] every policy must validate.
pub fn check_feedback(policy: &dyn Policy, feedback: &Feedback<'_>) -> Result<()> {
    feedback.context.check_dim(policy.dim())?;
    if feedback.arm.0 >= policy.n_arms() {
        return Err(HilError::ArmOutOfRange {
            arm: feedback.arm.0,
            n_arms: policy.n_arms(),
        });
    }
    if !feedback.reward.is_finite() {
        return Err(HilError::invalid_input(
            "reward",
            format!("{} is not finite", feedback.reward),
        ));
    }
    Ok(())
}
