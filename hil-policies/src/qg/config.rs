//! `type = "linucb_qg"` in experiment configs.

use hil_core::{QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::LinUcbQgParams;
use crate::config::{LinearPolicyConfig, RuleConfig};

/// Config for [`crate::LinUcbQg`].
///
/// ```toml
/// [policy]
/// type = "linucb_qg"
/// alpha = 0.5
/// w = 0.2
/// pretrain = true
/// query_kind = { response = "mcq", difficulty = "easy", distraction = "none" }
/// ```
pub type LinUcbQgConfig = LinearPolicyConfig<LinUcbQgFields>;

/// LinUCB-QG's own config fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbQgFields {
    /// Workload weight w ≥ 0.
    pub w: f64,
}

impl RuleConfig for LinUcbQgFields {
    type Rule = LinUcbQgParams;
    const FIELDS: &'static [&'static str] = &["w"];
    const ASKS: bool = true;
    const USES_WORKLOAD_FORECAST: bool = true;
    const STOCHASTIC: bool = false;
    const EXAMPLE: &'static [(&'static str, f64)] = &[("w", 0.2)];
    fn params(&self, alpha: f64, query_kind: QueryKind) -> Result<LinUcbQgParams> {
        LinUcbQgParams::new(alpha, self.w, query_kind)
    }
}
