//! NASA-TLX scoring: the paper's querying-workload score.
//!
//! Each of the five modified TLX subscales is answered on a 5-point Likert
//! scale (1..=5). Answers are normalised to [0, 1] as `(a - 1) / 4` and the
//! workload score is `WL = 0.4·mental + 0.2·temporal + 0.4·effort`
//! (performance and frustration are recorded but not scored).

use hil_core::{HilError, Result};
use serde::{Deserialize, Serialize};

/// Weight of the mental (or mental/physical) demand subscale.
pub const W_MENTAL: f64 = 0.4;
/// Weight of the temporal demand subscale.
pub const W_TEMPORAL: f64 = 0.2;
/// Weight of the effort subscale.
pub const W_EFFORT: f64 = 0.4;

/// The five modified TLX answers of one survey, each in 1..=5.
///
/// ```
/// use hil_workload::tlx::TlxAnswers;
/// let a = TlxAnswers::new(3, 1, 4, 5, 2).unwrap();
/// // 0.4·0.5 + 0.2·0 + 0.4·1
/// assert!((a.workload() - 0.6).abs() < 1e-12);
/// assert!(TlxAnswers::new(0, 1, 1, 1, 1).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TlxAnswers {
    /// Mental (or mental/physical) demand.
    pub mental: u8,
    /// Temporal demand (how hurried).
    pub temporal: u8,
    /// Performance (how successful).
    pub performance: u8,
    /// Effort.
    pub effort: u8,
    /// Frustration.
    pub frustration: u8,
}

/// Normalises a Likert answer in 1..=5 to [0, 1].
pub fn normalise(answer: u8) -> f64 {
    f64::from(answer.saturating_sub(1)) / 4.0
}

/// Checks one Likert answer.
pub fn check_likert(name: &str, answer: u8) -> Result<u8> {
    if (1..=5).contains(&answer) {
        Ok(answer)
    } else {
        Err(HilError::invalid_parameter(
            name,
            answer,
            "a TLX answer must be an integer in 1..=5",
        ))
    }
}

impl TlxAnswers {
    /// Builds a survey, checking every answer is in 1..=5.
    pub fn new(
        mental: u8,
        temporal: u8,
        performance: u8,
        effort: u8,
        frustration: u8,
    ) -> Result<Self> {
        Ok(Self {
            mental: check_likert("mental", mental)?,
            temporal: check_likert("temporal", temporal)?,
            performance: check_likert("performance", performance)?,
            effort: check_likert("effort", effort)?,
            frustration: check_likert("frustration", frustration)?,
        })
    }

    /// The querying-workload score in [0, 1].
    pub fn workload(&self) -> f64 {
        W_MENTAL * normalise(self.mental)
            + W_TEMPORAL * normalise(self.temporal)
            + W_EFFORT * normalise(self.effort)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extremes_and_weights() {
        assert_eq!(TlxAnswers::new(1, 1, 5, 1, 5).unwrap().workload(), 0.0);
        assert!((TlxAnswers::new(5, 5, 1, 5, 1).unwrap().workload() - 1.0).abs() < 1e-12);
        assert!((TlxAnswers::new(1, 5, 1, 1, 1).unwrap().workload() - 0.2).abs() < 1e-12);
        assert!(TlxAnswers::new(1, 1, 1, 6, 1).is_err());
    }
}
