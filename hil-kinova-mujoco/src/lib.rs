//! # hil-kinova-mujoco
//!
//! A Kinova Gen3 feeding environment simulated in MuJoCo.
//!
//! Status: not implemented yet (tracked by the MuJoCo issue). This crate
//! currently exports nothing.

/// Does nothing; calling it keeps this crate (and its typetag registrations)
/// linked into a binary that names its components only in configs.
pub fn link() {}
