//! LinUCB-ExpDecay: on the first timestep of an item, ask with probability
//! exp(−c·N), N being the number of items seen so far; otherwise act as LinUCB.

mod config;
mod rng_state;

pub use config::{LinUcbExpDecayConfig, LinUcbExpDecayFields};

use hil_core::{ArmId, Decision, DecisionInput, Diagnostics, QueryKind, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::estimator::ArmEstimate;
use crate::policy::{LinearPolicy, QueryRule};

/// LinUCB-ExpDecay hyperparameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbExpDecayParams {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Decay rate c ≥ 0 of the query probability exp(−c·N).
    pub c: f64,
    /// What to ask.
    pub query_kind: QueryKind,
}

impl LinUcbExpDecayParams {
    /// Validated parameters.
    pub fn new(alpha: f64, c: f64, query_kind: QueryKind) -> Result<Self> {
        crate::params::alpha(alpha)?;
        crate::params::non_negative("c", c, "the query-probability decay rate")?;
        Ok(Self {
            alpha,
            c,
            query_kind,
        })
    }

    /// The query probability after `items_seen` items.
    pub fn query_probability(&self, items_seen: usize) -> f64 {
        (-self.c * items_seen as f64).exp()
    }
}

/// A naive querying baseline with its own seeded randomness
/// ([`hil_core::Policy::seed`]; the RNG state is part of checkpoints).
///
/// ```
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, QueryKind, WorkloadForecast};
/// use hil_policies::{LinUcbExpDecay, LinUcbExpDecayParams, LinearArms};
///
/// // c = 0: the first timestep of every item is a query.
/// let params = LinUcbExpDecayParams::new(1.0, 0.0, QueryKind::default()).unwrap();
/// let mut p = LinUcbExpDecay::new(params, LinearArms::new(2, 2, 1.0).unwrap());
/// p.seed(7);
/// let x = Context::new(vec![0.0, 1.0]).unwrap();
/// let h = QueryHistory::new();
/// let mut input = DecisionInput {
///     context: &x, t: 1, item_index: 3, items_seen: 3, attempt: 0,
///     workload: WorkloadForecast::none(&h),
/// };
/// assert!(matches!(p.decide(&input).unwrap().choice, Choice::Query { .. }));
/// input.attempt = 1; // later attempts never query
/// assert!(matches!(p.decide(&input).unwrap().choice, Choice::Act { .. }));
/// ```
pub type LinUcbExpDecay = LinearPolicy<LinUcbExpDecayRule>;

/// The rule of [`LinUcbExpDecay`]: its parameters and its RNG, seeded
/// with 0 until [`hil_core::Policy::seed`] is called.
#[derive(Clone, Debug)]
pub struct LinUcbExpDecayRule {
    params: LinUcbExpDecayParams,
    rng: ChaCha8Rng,
}

impl QueryRule for LinUcbExpDecayRule {
    const NAME: &'static str = "linucb_exp_decay";
    type Params = LinUcbExpDecayParams;
    fn from_params(params: LinUcbExpDecayParams) -> Self {
        Self {
            params,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }
    fn params(&self) -> LinUcbExpDecayParams {
        self.params
    }
    fn alpha(&self) -> f64 {
        self.params.alpha
    }
    fn decide(
        &mut self,
        _scores: &[ArmEstimate],
        ucb_arm: ArmId,
        input: &DecisionInput<'_>,
        diag: &mut Diagnostics,
    ) -> Result<Decision> {
        if input.attempt != 0 {
            return Ok(Decision::act(ucb_arm));
        }
        let p = self.params.query_probability(input.items_seen);
        diag.query_probability = Some(p);
        // One draw per item's first timestep, whatever p is, so the random
        // stream does not depend on the decay rate.
        let u: f64 = self.rng.random();
        Ok(if u < p {
            Decision::query(self.params.query_kind, ucb_arm)
        } else {
            Decision::act(ucb_arm)
        })
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn save_state(&self) -> Value {
        rng_state::save(&self.rng)
    }
    fn restore_state(&mut self, state: Value) -> Result<()> {
        self.rng = rng_state::restore(state)?;
        Ok(())
    }
}
