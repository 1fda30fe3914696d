//! AlwaysQuery: ask for every item; fall back to the LinUCB arm if the
//! person declines or times out.

mod config;

pub use config::AlwaysQueryConfig;

use hil_core::{Decision, DecisionInput, Feedback, Policy, QueryKind, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::common;
use crate::estimator::LinearArms;

/// AlwaysQuery hyperparameters.
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
/// let input = DecisionInput {
///     context: &x, t: 1, item_index: 0, items_seen: 0, attempt: 0,
///     workload: WorkloadForecast::none(&h),
/// };
/// assert!(matches!(p.decide(&input).unwrap().choice, Choice::Query { .. }));
/// ```
#[derive(Clone, Debug)]
pub struct AlwaysQuery {
    params: AlwaysQueryParams,
    arms: LinearArms,
}

impl AlwaysQuery {
    /// AlwaysQuery over `arms` (possibly pretrained).
    pub fn new(params: AlwaysQueryParams, arms: LinearArms) -> Self {
        Self { params, arms }
    }

    /// The parameters.
    pub fn params(&self) -> AlwaysQueryParams {
        self.params
    }

    /// The estimator.
    pub fn estimator(&self) -> &LinearArms {
        &self.arms
    }
}

impl Policy for AlwaysQuery {
    fn name(&self) -> &str {
        "always_query"
    }
    fn n_arms(&self) -> usize {
        self.arms.n_arms()
    }
    fn dim(&self) -> usize {
        self.arms.dim()
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let (s, diag) = common::score(&mut self.arms, input, self.params.alpha)?;
        let fallback = common::ucb_arm(&s, self.params.alpha);
        Ok(Decision::query(self.params.query_kind, fallback).with_diagnostics(diag))
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        common::learn(&mut self.arms, feedback)
    }
    fn save(&self) -> Result<Value> {
        Ok(common::save(self.name(), &self.arms, Value::Null))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let (arms, _) = common::restore(self, state)?;
        self.arms = arms;
        Ok(())
    }
}
