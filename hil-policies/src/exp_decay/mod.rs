//! LinUCB-ExpDecay: on the first timestep of an item, ask with probability
//! exp(−c·N), N being the item's number counted from 1 (the current item
//! counts, as in the paper: its f_q of 0.160 for c = 0.8 is exactly the mean
//! of exp(−0.8·N) over N = 1..5); otherwise act as LinUCB.

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

    /// The query probability exp(−c·N) at the first timestep of item
    /// number `n` (counted from 1: the first item has N = 1).
    ///
    /// ```
    /// use hil_core::QueryKind;
    /// use hil_policies::LinUcbExpDecayParams;
    /// let p = LinUcbExpDecayParams::new(1.0, 0.8, QueryKind::default()).unwrap();
    /// // The paper's f_q = 0.160 for c = 0.8 over five test items.
    /// let f_q: f64 = (1..=5).map(|n| p.query_probability(n)).sum::<f64>() / 5.0;
    /// assert!((f_q - 0.160).abs() < 5e-4);
    /// ```
    pub fn query_probability(&self, n: usize) -> f64 {
        (-self.c * n as f64).exp()
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
/// let input = DecisionInput::new(&x, 1, WorkloadForecast::none(&h)).at_item(3, 3, 0);
/// assert!(matches!(p.decide(&input).unwrap().choice, Choice::Query { .. }));
/// let input = input.at_item(3, 3, 1); // later attempts never query
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
        // `items_seen` counts the items before this one; the paper's N
        // counts this one too.
        let p = self.query_probability(ctx.input.items_seen + 1);
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

#[cfg(test)]
mod tests {
    use hil_core::{Context, DecisionInput, Policy, QueryHistory, QueryKind, WorkloadForecast};

    use super::*;
    use crate::LinearArms;

    /// Through the policy: the probability at item n's first timestep is
    /// exp(−c·n) with n counted from 1, so over the paper's five test items
    /// the expected f_q gives the paper's 0.160 (c = 0.8) and 0.440 (c = 0.3)
    /// (counting from 0 would give 0.357 and 0.599).
    #[test]
    fn the_current_item_counts_as_in_the_paper() {
        for (c, paper_f_q) in [(0.8, 0.160), (0.3, 0.440)] {
            let params = LinUcbExpDecayParams::new(1.0, c, QueryKind::default()).unwrap();
            let mut p = LinUcbExpDecay::new(params, LinearArms::new(2, 2, 1.0).unwrap());
            p.seed(1);
            let x = Context::new(vec![0.0, 1.0]).unwrap();
            let h = QueryHistory::new();
            let probs: Vec<f64> = (0..5)
                .map(|items_seen| {
                    let input =
                        DecisionInput::new(&x, 1 + items_seen as u64, WorkloadForecast::none(&h))
                            .at_item(items_seen, items_seen, 0);
                    p.decide(&input)
                        .unwrap()
                        .diagnostics
                        .query_probability
                        .unwrap()
                })
                .collect();
            for (i, q) in probs.iter().enumerate() {
                assert!((q - (-c * (i + 1) as f64).exp()).abs() < 1e-12);
            }
            // The paper's f_q is a count over 75 first attempts (3 seeds ×
            // 5 policy seeds × 5 items): the expected count, rounded, is it.
            let f_q = probs.iter().sum::<f64>() / 5.0;
            let count = (f_q * 75.0).round();
            assert!((count / 75.0 - paper_f_q).abs() < 1e-9, "c = {c}: {f_q}");
        }
    }
}
