//! `type = "linucb"` in experiment configs.

use hil_core::{QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::LinUcbParams;
use crate::config::{LinearPolicyConfig, RuleConfig};

/// Config for [`crate::LinUcb`]: only the shared fields (no `query_kind`,
/// it never asks).
///
/// ```toml
/// [policy]
/// type = "linucb"
/// alpha = 0.5
/// lambda = 1.0        # default 1
/// pretrain = true     # fit on the environment's pretraining data first
/// ```
pub type LinUcbConfig = LinearPolicyConfig<LinUcbFields>;

/// LinUCB's own config fields: none.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinUcbFields {}

impl RuleConfig for LinUcbFields {
    type Rule = LinUcbParams;
    const FIELDS: &'static [&'static str] = &[];
    const ASKS: bool = false;
    const USES_WORKLOAD_FORECAST: bool = false;
    const STOCHASTIC: bool = false;
    fn params(&self, alpha: f64, _query_kind: QueryKind) -> Result<LinUcbParams> {
        LinUcbParams::new(alpha)
    }
}
