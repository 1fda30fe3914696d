//! `type = "always_query"` in experiment configs.

use hil_core::{QueryKind, Result};
use serde::{Deserialize, Serialize};

use super::AlwaysQueryParams;
use crate::config::{LinearPolicyConfig, RuleConfig};

/// Config for [`crate::AlwaysQuery`]: only the shared fields.
///
/// ```toml
/// [policy]
/// type = "always_query"
/// alpha = 0.5
/// pretrain = true
/// query_kind = { response = "mcq", difficulty = "easy", distraction = "none" }
/// ```
pub type AlwaysQueryConfig = LinearPolicyConfig<AlwaysQueryFields>;

/// AlwaysQuery's own config fields: none.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlwaysQueryFields {}

impl RuleConfig for AlwaysQueryFields {
    type Rule = AlwaysQueryParams;
    const FIELDS: &'static [&'static str] = &[];
    const ASKS: bool = true;
    const USES_WORKLOAD_FORECAST: bool = false;
    const STOCHASTIC: bool = false;
    fn params(&self, alpha: f64, query_kind: QueryKind) -> Result<AlwaysQueryParams> {
        AlwaysQueryParams::new(alpha, query_kind)
    }
}
