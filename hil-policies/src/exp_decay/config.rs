//! `type = "linucb_exp_decay"` in experiment configs.

use hil_core::config::PolicyConfig;
use hil_core::{BuildContext, Policy, QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::{LinUcbExpDecay, LinUcbExpDecayParams};
use crate::common;
use crate::estimator::EstimatorOptions;

/// Config for [`LinUcbExpDecay`]. The policy is seeded from the experiment
/// seed unless `seed` is given.
///
/// ```toml
/// [policy]
/// type = "linucb_exp_decay"
/// alpha = 0.5
/// c = 0.3
/// pretrain = true
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbExpDecayConfig {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Decay rate c ≥ 0.
    pub c: f64,
    /// Ridge strength λ > 0.
    #[serde(default = "common::default_lambda")]
    pub lambda: f64,
    /// Pretrain on the environment's offline data (an error if it has none).
    #[serde(default)]
    pub pretrain: bool,
    /// What to ask (default: easy multiple choice, no distraction).
    #[serde(default)]
    pub query_kind: QueryKind,
    /// Policy seed (default: the experiment seed).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Estimator representation options.
    #[serde(default)]
    pub estimator: EstimatorOptions,
}

#[typetag::serde(name = "linucb_exp_decay")]
impl PolicyConfig for LinUcbExpDecayConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Policy>> {
        let params = LinUcbExpDecayParams::new(self.alpha, self.c, self.query_kind)?;
        let arms = common::build_estimator(ctx, self.lambda, self.pretrain, self.estimator)?;
        let mut p = LinUcbExpDecay::new(params, arms);
        p.seed(self.seed.unwrap_or(ctx.seed));
        Ok(Box::new(p))
    }
}
