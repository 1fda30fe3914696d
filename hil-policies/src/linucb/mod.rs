//! LinUCB: act with the arm of largest upper confidence bound θᵀx + α·b(x).

mod config;

pub use config::{LinUcbConfig, LinUcbFields};

use hil_core::{Decision, Result};
use serde::{Deserialize, Serialize};

use crate::policy::{LinearPolicy, QueryRule, RuleContext};

/// LinUCB hyperparameters (λ lives in the estimator); also its rule, which
/// has no state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbParams {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
}

impl LinUcbParams {
    /// Validated parameters.
    pub fn new(alpha: f64) -> Result<Self> {
        crate::params::alpha(alpha)?;
        Ok(Self { alpha })
    }
}

/// The fully autonomous baseline: never queries.
///
/// ```
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, WorkloadForecast};
/// use hil_policies::{LinUcb, LinUcbParams, LinearArms};
///
/// let mut p = LinUcb::new(LinUcbParams::new(1.0).unwrap(), LinearArms::new(3, 2, 1.0).unwrap());
/// let x = Context::new(vec![1.0, 0.0]).unwrap();
/// let h = QueryHistory::new();
/// let input = DecisionInput::new(&x, 1, WorkloadForecast::none(&h));
/// let d = p.decide(&input).unwrap();
/// assert!(matches!(d.choice, Choice::Act { .. }));
/// assert_eq!(d.diagnostics.arms.len(), 3);
/// ```
pub type LinUcb = LinearPolicy<LinUcbParams>;

impl QueryRule for LinUcbParams {
    const NAME: &'static str = "linucb";
    type State = ();
    fn alpha(&self) -> f64 {
        self.alpha
    }
    fn decide(&self, _: &mut (), ctx: RuleContext<'_, '_>) -> Result<Decision> {
        Ok(Decision::act(ctx.ucb_arm))
    }
}
