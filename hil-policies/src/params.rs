//! Validation shared by every hyperparameter struct.

use hil_core::{HilError, Result};

/// Checks that `value` is finite and ≥ 0, naming it in the error.
pub(crate) fn non_negative(name: &str, value: f64, meaning: &str) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(HilError::invalid_parameter(
            name,
            value,
            format!("{meaning} must be a finite number ≥ 0"),
        ))
    }
}

/// Checks the exploration weight α.
pub(crate) fn alpha(value: f64) -> Result<()> {
    non_negative("alpha", value, "the confidence-bonus weight")
}
