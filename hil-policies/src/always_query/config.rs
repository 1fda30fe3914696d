//! `type = "always_query"` in experiment configs.

use hil_core::config::PolicyConfig;
use hil_core::{BuildContext, Policy, QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::{AlwaysQuery, AlwaysQueryParams};
use crate::common;
use crate::estimator::EstimatorOptions;

/// Config for [`AlwaysQuery`].
///
/// ```toml
/// [policy]
/// type = "always_query"
/// alpha = 0.5
/// pretrain = true
/// query_kind = { response = "mcq", difficulty = "easy", distraction = "none" }
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlwaysQueryConfig {
    /// Weight α ≥ 0 of the confidence bonus in the fallback arm.
    pub alpha: f64,
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

#[typetag::serde(name = "always_query")]
impl PolicyConfig for AlwaysQueryConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Policy>> {
        let params = AlwaysQueryParams::new(self.alpha, self.query_kind)?;
        let arms = common::build_estimator(ctx, self.lambda, self.pretrain, self.estimator)?;
        Ok(Box::new(AlwaysQuery::new(params, arms)))
    }
}
