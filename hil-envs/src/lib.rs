//! # hil-envs
//!
//! The dataset-replay environment and the paper's simulated testbed.
//!
//! Status: not implemented yet (tracked by the environments issue). This
//! crate currently exports nothing.

/// Does nothing; calling it keeps this crate (and its typetag registrations)
/// linked into a binary that names its components only in configs.
pub fn link() {}
