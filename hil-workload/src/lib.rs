//! # hil-workload
//!
//! Querying-workload models learned from NASA-TLX study data: scoring,
//! study data, Granger / Exp-Impulse models, constrained fitting and
//! cross-validated selection.
//!
//! Status: not implemented yet (tracked by the workload issue). This crate
//! currently exports nothing.

/// Does nothing; calling it keeps this crate (and its typetag registrations)
/// linked into a binary that names its components only in configs.
pub fn link() {}
