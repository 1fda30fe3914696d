//! The Average baseline: the mean WL_0 of the training set.

use hil_core::{HilError, Result, WorkloadModel, workload::check_wl0};
use serde::{Deserialize, Serialize};

use crate::datasets::TrainingPair;
use hil_core::WorkloadInput;

/// Predicts the training set's mean initial workload, whatever happens.
///
/// ```
/// use hil_core::{QueryHistory, WorkloadInput, WorkloadModel};
/// use hil_workload::models::AverageModel;
/// let m = AverageModel { value: 0.4 };
/// assert_eq!(m.predict(&WorkloadInput::new(0.9, &QueryHistory::new(), 5)).unwrap(), 0.4);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AverageModel {
    /// The predicted workload.
    pub value: f64,
}

impl AverageModel {
    /// Fits the mean WL_0 of `pairs`.
    pub fn fit(pairs: &[&TrainingPair]) -> Result<Self> {
        if pairs.is_empty() {
            return Err(HilError::invalid_input(
                "training set",
                "no pairs to average",
            ));
        }
        Ok(Self {
            value: hil_stats::mean(&pairs.iter().map(|p| p.wl0).collect::<Vec<_>>()),
        })
    }

    /// Checks the value is a workload in [0, 1].
    pub fn validate(&self) -> Result<()> {
        check_wl0(self.value)
            .map_err(|_| HilError::invalid_parameter("value", self.value, "must be in [0, 1]"))
    }
}

impl WorkloadModel for AverageModel {
    fn name(&self) -> &str {
        "average"
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        check_wl0(input.wl0)?;
        Ok(self.value)
    }
}
