//! The vocabulary of a hypothesis test: its alternative and its result.

use serde::{Deserialize, Serialize};

/// The alternative hypothesis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Alternative {
    /// The first sample is stochastically smaller (or differences < 0).
    Less,
    /// The first sample is stochastically greater (or differences > 0).
    Greater,
    /// Either direction.
    TwoSided,
}

/// A test statistic and its p-value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestResult {
    /// U of the first sample (Mann-Whitney) or W+ (Wilcoxon).
    pub statistic: f64,
    /// The p-value under the chosen alternative.
    pub p_value: f64,
    /// True if the exact null distribution was used.
    pub exact: bool,
}
