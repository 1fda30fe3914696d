//! `type = "linucb_exp_decay"` in experiment configs.

use hil_core::{QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::LinUcbExpDecayParams;
use crate::config::{LinearPolicyConfig, RuleConfig};

/// Config for [`crate::LinUcbExpDecay`]. The policy is seeded from the
/// experiment seed unless `seed` is given.
///
/// ```toml
/// [policy]
/// type = "linucb_exp_decay"
/// alpha = 0.5
/// c = 0.3
/// pretrain = true
/// ```
pub type LinUcbExpDecayConfig = LinearPolicyConfig<LinUcbExpDecayFields>;

/// LinUCB-ExpDecay's own config fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbExpDecayFields {
    /// Decay rate c ≥ 0.
    pub c: f64,
    /// Policy seed (default: the experiment seed).
    #[serde(default)]
    pub seed: Option<u64>,
}

impl RuleConfig for LinUcbExpDecayFields {
    type Rule = LinUcbExpDecayParams;
    const FIELDS: &'static [&'static str] = &["c", "seed"];
    const ASKS: bool = true;
    const USES_WORKLOAD_FORECAST: bool = false;
    const STOCHASTIC: bool = true;
    const EXAMPLE: &'static [(&'static str, f64)] = &[("c", 0.1)];
    fn params(&self, alpha: f64, query_kind: QueryKind) -> Result<LinUcbExpDecayParams> {
        LinUcbExpDecayParams::new(alpha, self.c, query_kind)
    }
    fn seed(&self) -> Option<u64> {
        self.seed
    }
}
