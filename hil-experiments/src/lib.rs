//! # hil-experiments
//!
//! The paper's protocols as library code, so that the `hil` binary, downstream
//! crates and tests run the same experiments: the simulated testbed, the
//! user-study protocol, aggregation with uncertainty, tables and figures, and
//! the paper's published tables as data.

// The real-robot user-study protocol (`hil demo kinova`).
pub mod user_study;
pub use user_study::{UserStudy, UserStudyConfig, UserStudyResult};
