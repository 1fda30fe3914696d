//! The integration tests of `hil-kinova-mujoco`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.
//! They need the MuJoCo simulation: `cargo test -p hil-kinova-mujoco
//! --features physics` (scripts/test turns it on).
#![cfg(feature = "physics")]

mod common;
mod kinova;
mod kinova_hold_roll;
mod kinova_pretrain;
mod kinova_step;
