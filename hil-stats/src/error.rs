//! Errors of the tests: a sample they cannot be computed on.

/// Why a test could not be computed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StatsError {
    /// A sample the test is undefined on; `sample` names which one
    /// (`first sample`, `paired samples`, ...).
    #[error("invalid {sample}: {reason}")]
    InvalidSample {
        /// The sample at fault.
        sample: &'static str,
        /// Why it was rejected, including the offending value.
        reason: String,
    },
}

impl StatsError {
    pub(crate) fn sample(sample: &'static str, reason: impl Into<String>) -> Self {
        Self::InvalidSample {
            sample,
            reason: reason.into(),
        }
    }
}

/// The result of a test.
pub type Result<T> = std::result::Result<T, StatsError>;
