//! The Constant baseline: WL_t = WL_0.

use hil_core::{QueryHistory, Result, Timestep, WorkloadModel, workload::check_wl0};
use serde::{Deserialize, Serialize};

/// Predicts that workload never changes: WL_t = WL_0.
///
/// ```
/// use hil_core::{QueryHistory, WorkloadModel};
/// use hil_workload::models::ConstantModel;
/// assert_eq!(ConstantModel {}.predict(0.3, &QueryHistory::new(), 5).unwrap(), 0.3);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantModel {}

impl WorkloadModel for ConstantModel {
    fn name(&self) -> &str {
        "constant"
    }

    fn predict(&self, wl0: f64, _history: &QueryHistory, _t: Timestep) -> Result<f64> {
        check_wl0(wl0)?;
        Ok(wl0)
    }
}
