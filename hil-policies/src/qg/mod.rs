//! LinUCB-QG (query gap): ask when the plausible second-best arm could beat
//! the best one by more than the weighted workload a query would cost.

mod config;
mod gap;

pub use config::LinUcbQgConfig;
pub use gap::{QueryGap, query_gap};

use hil_core::{Decision, DecisionInput, Feedback, Policy, QueryKind, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::common;
use crate::estimator::LinearArms;

/// LinUCB-QG hyperparameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbQgParams {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Workload weight w ≥ 0: query iff G > w·WL_t.
    pub w: f64,
    /// What to ask; WL_t is forecast for this kind.
    pub query_kind: QueryKind,
}

impl LinUcbQgParams {
    /// Validated parameters.
    pub fn new(alpha: f64, w: f64, query_kind: QueryKind) -> Result<Self> {
        crate::params::alpha(alpha)?;
        crate::params::non_negative("w", w, "the workload weight")?;
        Ok(Self {
            alpha,
            w,
            query_kind,
        })
    }
}

/// LinUCB-QG. With a* = argmax θᵀx and a⁻ the runner-up by θᵀx,
/// G = (θ_{a⁻}ᵀx + α·b_{a⁻}) − (θ_{a*}ᵀx − α·b_{a*}); it queries iff
/// G > w·WL_t, WL_t being the workload model's forecast if it queried now,
/// and otherwise acts with the LinUCB arm. With a single arm there is no
/// gap and it always acts.
///
/// ```
/// use hil_core::testing::fixtures::CountingWorkload;
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, QueryKind, WorkloadForecast};
/// use hil_policies::{LinUcbQg, LinUcbQgParams, LinearArms};
///
/// let params = LinUcbQgParams::new(1.0, 0.5, QueryKind::default()).unwrap();
/// let mut p = LinUcbQg::new(params, LinearArms::new(2, 2, 1.0).unwrap());
/// let x = Context::new(vec![0.0, 1.0]).unwrap();
/// let (model, h) = (CountingWorkload::new(0.1), QueryHistory::new());
/// let input = DecisionInput {
///     context: &x, t: 1, item_index: 0, items_seen: 0, attempt: 0,
///     workload: WorkloadForecast::new(Some(&model), 0.5, &h, 1),
/// };
/// // Nothing learnt yet: G = 2α·b = 2 > w·WL = 0.5 · 0.6.
/// let d = p.decide(&input).unwrap();
/// assert!(matches!(d.choice, Choice::Query { .. }));
/// assert!((d.diagnostics.gap.unwrap() - 2.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct LinUcbQg {
    params: LinUcbQgParams,
    arms: LinearArms,
}

impl LinUcbQg {
    /// LinUCB-QG over `arms` (possibly pretrained).
    pub fn new(params: LinUcbQgParams, arms: LinearArms) -> Self {
        Self { params, arms }
    }

    /// The parameters.
    pub fn params(&self) -> LinUcbQgParams {
        self.params
    }

    /// The estimator.
    pub fn estimator(&self) -> &LinearArms {
        &self.arms
    }
}

impl Policy for LinUcbQg {
    fn name(&self) -> &str {
        "linucb_qg"
    }
    fn n_arms(&self) -> usize {
        self.arms.n_arms()
    }
    fn dim(&self) -> usize {
        self.arms.dim()
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let p = self.params;
        let (s, mut diag) = common::score(&mut self.arms, input, p.alpha)?;
        let arm = common::ucb_arm(&s, p.alpha);
        let Some(g) = query_gap(&s, p.alpha) else {
            return Ok(Decision::act(arm).with_diagnostics(diag));
        };
        let wl = input.workload.if_queried(p.query_kind)?;
        let threshold = p.w * wl;
        diag.gap = Some(g.gap);
        diag.threshold = Some(threshold);
        diag.workload_forecast = Some(wl);
        let d = if g.gap > threshold {
            Decision::query(p.query_kind, arm)
        } else {
            Decision::act(arm)
        };
        Ok(d.with_diagnostics(diag))
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
