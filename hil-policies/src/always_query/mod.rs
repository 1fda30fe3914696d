//! AlwaysQuery: ask for every item; fall back to the LinUCB arm if the
//! person declines or times out.

mod config;

pub use config::{AlwaysQueryConfig, AlwaysQueryFields};

use hil_core::{Decision, QueryKind, Result};
use serde::{Deserialize, Serialize};

use crate::policy::{LinearPolicy, QueryRule, RuleContext};

/// AlwaysQuery hyperparameters; also its rule, which has no state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlwaysQueryParams {
    /// Weight α ≥ 0 of the confidence bonus in the fallback arm.
    pub alpha: f64,
    /// What to ask.
    pub query_kind: QueryKind,
}

impl AlwaysQueryParams {
    /// Validated parameters.
    pub fn new(alpha: f64, query_kind: QueryKind) -> Result<Self> {
        crate::params::alpha(alpha)?;
        Ok(Self { alpha, query_kind })
    }
}

/// Queries at every decision. The session loop repeats the expert's arm
/// after a query, so `decide` is only called again at an item when the
/// person gave no usable answer; it then asks again.
///
/// ```
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, QueryKind, WorkloadForecast};
/// use hil_policies::{AlwaysQuery, AlwaysQueryParams, LinearArms};
///
/// let params = AlwaysQueryParams::new(1.0, QueryKind::default()).unwrap();
/// let mut p = AlwaysQuery::new(params, LinearArms::new(2, 2, 1.0).unwrap());
/// let x = Context::new(vec![0.0, 1.0]).unwrap();
/// let h = QueryHistory::new();
/// let input = DecisionInput::new(&x, 1, WorkloadForecast::none(&h));
/// assert!(matches!(p.decide(&input).unwrap().choice, Choice::Query { .. }));
/// ```
pub type AlwaysQuery = LinearPolicy<AlwaysQueryParams>;

impl QueryRule for AlwaysQueryParams {
    const NAME: &'static str = "always_query";
    type State = ();
    fn alpha(&self) -> f64 {
        self.alpha
    }
    fn decide(&self, _: &mut (), ctx: RuleContext<'_, '_>) -> Result<Decision> {
        Ok(Decision::query(self.query_kind, ctx.ucb_arm))
    }
}
