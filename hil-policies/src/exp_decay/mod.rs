//! LinUCB-ExpDecay: on the first timestep of an item, ask with probability
//! exp(−c·N), N being the number of items seen so far; otherwise act as LinUCB.

mod config;
mod rng_state;

pub use config::{LinUcbExpDecayConfig, LinUcbExpDecayFields};

use hil_core::{Decision, QueryKind, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::policy::{LinearPolicy, QueryRule, RuleContext};

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
pub type LinUcbExpDecay = LinearPolicy<LinUcbExpDecayParams>;

/// LinUCB-ExpDecay's state: its RNG, seeded with 0 until
/// [`hil_core::Policy::seed`] is called.
#[derive(Clone, Debug)]
pub struct ExpDecayRng(ChaCha8Rng);

impl Default for ExpDecayRng {
    fn default() -> Self {
        Self(ChaCha8Rng::seed_from_u64(0))
    }
}

impl QueryRule for LinUcbExpDecayParams {
    const NAME: &'static str = "linucb_exp_decay";
    type State = ExpDecayRng;
    fn alpha(&self) -> f64 {
        self.alpha
    }
    fn decide(&self, rng: &mut ExpDecayRng, ctx: RuleContext<'_, '_>) -> Result<Decision> {
        if ctx.input.attempt != 0 {
            return Ok(Decision::act(ctx.ucb_arm));
        }
        let p = self.query_probability(ctx.input.items_seen);
        ctx.diagnostics.query_probability = Some(p);
        // One draw per item's first timestep, whatever p is, so the random
        // stream does not depend on the decay rate.
        let u: f64 = rng.0.random();
        Ok(if u < p {
            Decision::query(self.query_kind, ctx.ucb_arm)
        } else {
            Decision::act(ctx.ucb_arm)
        })
    }
    fn seed(rng: &mut ExpDecayRng, seed: u64) {
        rng.0 = ChaCha8Rng::seed_from_u64(seed);
    }
    fn save_state(rng: &ExpDecayRng) -> Value {
        rng_state::save(&rng.0)
    }
    fn restore_state(rng: &mut ExpDecayRng, saved: Value) -> Result<()> {
        rng.0 = rng_state::restore(saved)?;
        Ok(())
    }
}
