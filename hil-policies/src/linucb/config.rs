//! `type = "linucb"` in experiment configs.

use hil_core::config::PolicyConfig;
use hil_core::{BuildContext, Policy, Result};
use serde::{Deserialize, Serialize};

use super::{LinUcb, LinUcbParams};
use crate::common;
use crate::estimator::EstimatorOptions;

/// Config for [`LinUcb`].
///
/// ```toml
/// [policy]
/// type = "linucb"
/// alpha = 0.5
/// lambda = 1.0        # default 1
/// pretrain = true     # fit on the environment's pretraining data first
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbConfig {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Ridge strength λ > 0.
    #[serde(default = "common::default_lambda")]
    pub lambda: f64,
    /// Pretrain on the environment's offline data (an error if it has none).
    #[serde(default)]
    pub pretrain: bool,
    /// Estimator representation options.
    #[serde(default)]
    pub estimator: EstimatorOptions,
}

#[typetag::serde(name = "linucb")]
impl PolicyConfig for LinUcbConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Policy>> {
        let params = LinUcbParams::new(self.alpha)?;
        let arms = common::build_estimator(ctx, self.lambda, self.pretrain, self.estimator)?;
        Ok(Box::new(LinUcb::new(params, arms)))
    }
}
