//! LinUCB: act with the arm of largest upper confidence bound θᵀx + α·b(x).

mod config;

pub use config::LinUcbConfig;

use hil_core::{Decision, DecisionInput, Feedback, Policy, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::common;
use crate::estimator::LinearArms;

/// LinUCB hyperparameters (λ lives in the estimator).
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
/// let input = DecisionInput {
///     context: &x, t: 1, item_index: 0, items_seen: 0, attempt: 0,
///     workload: WorkloadForecast::none(&h),
/// };
/// let d = p.decide(&input).unwrap();
/// assert!(matches!(d.choice, Choice::Act { .. }));
/// assert_eq!(d.diagnostics.arms.len(), 3);
/// ```
#[derive(Clone, Debug)]
pub struct LinUcb {
    params: LinUcbParams,
    arms: LinearArms,
}

impl LinUcb {
    /// LinUCB over `arms` (possibly pretrained).
    pub fn new(params: LinUcbParams, arms: LinearArms) -> Self {
        Self { params, arms }
    }

    /// The parameters.
    pub fn params(&self) -> LinUcbParams {
        self.params
    }

    /// The estimator.
    pub fn estimator(&self) -> &LinearArms {
        &self.arms
    }
}

impl Policy for LinUcb {
    fn name(&self) -> &str {
        "linucb"
    }
    fn n_arms(&self) -> usize {
        self.arms.n_arms()
    }
    fn dim(&self) -> usize {
        self.arms.dim()
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let (s, diag) = common::score(&mut self.arms, input, self.params.alpha)?;
        Ok(Decision::act(common::ucb_arm(&s, self.params.alpha)).with_diagnostics(diag))
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
