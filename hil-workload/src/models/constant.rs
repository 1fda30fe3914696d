//! The Constant baseline: WL_t = WL_0.

use hil_core::WorkloadInput;
use hil_core::{Result, WorkloadModel, workload::check_wl0};
use serde::{Deserialize, Serialize};

/// Predicts that workload never changes: WL_t = WL_0.
///
/// ```
/// use hil_core::{QueryHistory, WorkloadInput, WorkloadModel};
/// use hil_workload::models::ConstantModel;
/// assert_eq!(ConstantModel {}.predict(&WorkloadInput::new(0.3, &QueryHistory::new(), 5)).unwrap(), 0.3);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantModel {}

impl WorkloadModel for ConstantModel {
    fn name(&self) -> &str {
        "constant"
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        check_wl0(input.wl0)?;
        Ok(input.wl0)
    }
}
