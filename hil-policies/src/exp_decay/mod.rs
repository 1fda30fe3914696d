//! LinUCB-ExpDecay: on the first timestep of an item, ask with probability
//! exp(−c·N), N being the number of items seen so far; otherwise act as LinUCB.

mod config;
mod rng_state;

pub use config::LinUcbExpDecayConfig;

use hil_core::{Decision, DecisionInput, Feedback, Policy, QueryKind, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::common;
use crate::estimator::LinearArms;

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
/// ([`Policy::seed`]; the RNG state is part of checkpoints).
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
#[derive(Clone, Debug)]
pub struct LinUcbExpDecay {
    params: LinUcbExpDecayParams,
    arms: LinearArms,
    rng: ChaCha8Rng,
}

impl LinUcbExpDecay {
    /// LinUCB-ExpDecay over `arms` (possibly pretrained), seeded with 0
    /// until [`Policy::seed`] is called.
    pub fn new(params: LinUcbExpDecayParams, arms: LinearArms) -> Self {
        Self {
            params,
            arms,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }

    /// The parameters.
    pub fn params(&self) -> LinUcbExpDecayParams {
        self.params
    }

    /// The estimator.
    pub fn estimator(&self) -> &LinearArms {
        &self.arms
    }
}

impl Policy for LinUcbExpDecay {
    fn name(&self) -> &str {
        "linucb_exp_decay"
    }
    fn n_arms(&self) -> usize {
        self.arms.n_arms()
    }
    fn dim(&self) -> usize {
        self.arms.dim()
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let (s, mut diag) = common::score(&mut self.arms, input, self.params.alpha)?;
        let arm = common::ucb_arm(&s, self.params.alpha);
        if input.attempt != 0 {
            return Ok(Decision::act(arm).with_diagnostics(diag));
        }
        let p = self.params.query_probability(input.items_seen);
        diag.query_probability = Some(p);
        // One draw per item's first timestep, whatever p is, so the random
        // stream does not depend on the decay rate.
        let u: f64 = self.rng.random();
        let d = if u < p {
            Decision::query(self.params.query_kind, arm)
        } else {
            Decision::act(arm)
        };
        Ok(d.with_diagnostics(diag))
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        common::learn(&mut self.arms, feedback)
    }
    fn save(&self) -> Result<Value> {
        Ok(common::save(
            self.name(),
            &self.arms,
            rng_state::save(&self.rng),
        ))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let (arms, extra) = common::restore(self, state)?;
        let rng = rng_state::restore(extra)?;
        self.arms = arms;
        self.rng = rng;
        Ok(())
    }
}
