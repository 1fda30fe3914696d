//! `type = "linucb_qg"` in experiment configs.

use hil_core::config::PolicyConfig;
use hil_core::{BuildContext, Policy, QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::{LinUcbQg, LinUcbQgParams};
use crate::common;
use crate::estimator::EstimatorOptions;

/// Config for [`LinUcbQg`].
///
/// ```toml
/// [policy]
/// type = "linucb_qg"
/// alpha = 0.5
/// w = 0.2
/// pretrain = true
/// query_kind = { response = "mcq", difficulty = "easy", distraction = "none" }
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbQgConfig {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Workload weight w ≥ 0.
    pub w: f64,
    /// Ridge strength λ > 0.
    #[serde(default = "common::default_lambda")]
    pub lambda: f64,
    /// Pretrain on the environment's offline data (an error if it has none).
    #[serde(default)]
    pub pretrain: bool,
    /// What to ask (default: easy multiple choice, no distraction).
    #[serde(default)]
    pub query_kind: QueryKind,
    /// Estimator representation options.
    #[serde(default)]
    pub estimator: EstimatorOptions,
}

#[typetag::serde(name = "linucb_qg")]
impl PolicyConfig for LinUcbQgConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Policy>> {
        let params = LinUcbQgParams::new(self.alpha, self.w, self.query_kind)?;
        let arms = common::build_estimator(ctx, self.lambda, self.pretrain, self.estimator)?;
        Ok(Box::new(LinUcbQg::new(params, arms)))
    }
}
