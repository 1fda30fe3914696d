//! LinUCB-QG (query gap): ask when the plausible second-best arm could beat
//! the best one by more than the weighted workload a query would cost.

mod config;
mod gap;

pub use config::{LinUcbQgConfig, LinUcbQgFields};
pub use gap::{QueryGap, query_gap};

use hil_core::{Decision, QueryKind, Result};
use serde::{Deserialize, Serialize};

use crate::policy::{LinearPolicy, QueryRule, RuleContext};

/// LinUCB-QG hyperparameters; also its rule, which has no state.
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
/// use hil_conformance::fixtures::CountingWorkload;
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, QueryKind, WorkloadForecast};
/// use hil_policies::{LinUcbQg, LinUcbQgParams, LinearArms};
///
/// let params = LinUcbQgParams::new(1.0, 0.5, QueryKind::default()).unwrap();
/// let mut p = LinUcbQg::new(params, LinearArms::new(2, 2, 1.0).unwrap());
/// let x = Context::new(vec![0.0, 1.0]).unwrap();
/// let (model, h) = (CountingWorkload::new(0.1), QueryHistory::new());
/// let input = DecisionInput::new(&x, 1, WorkloadForecast::new(Some(&model), 0.5, &h, 1));
/// // Nothing learnt yet: G = 2α·b = 2 > w·WL = 0.5 · 0.6.
/// let d = p.decide(&input).unwrap();
/// assert!(matches!(d.choice, Choice::Query { .. }));
/// assert!((d.diagnostics.gap.unwrap() - 2.0).abs() < 1e-12);
/// ```
pub type LinUcbQg = LinearPolicy<LinUcbQgParams>;

impl QueryRule for LinUcbQgParams {
    const NAME: &'static str = "linucb_qg";
    type State = ();
    fn alpha(&self) -> f64 {
        self.alpha
    }
    fn decide(&self, _: &mut (), ctx: RuleContext<'_, '_>) -> Result<Decision> {
        let Some(g) = query_gap(ctx.scores, self.alpha) else {
            return Ok(Decision::act(ctx.ucb_arm));
        };
        let wl = ctx.input.workload.if_queried(self.query_kind)?;
        let threshold = self.w * wl;
        ctx.diagnostics.gap = Some(g.gap);
        ctx.diagnostics.threshold = Some(threshold);
        ctx.diagnostics.workload_forecast = Some(wl);
        Ok(if g.gap > threshold {
            Decision::query(self.query_kind, ctx.ucb_arm)
        } else {
            Decision::act(ctx.ucb_arm)
        })
    }
}
