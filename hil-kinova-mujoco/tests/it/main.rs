//! The integration tests of `hil-kinova-mujoco`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod kinova;
mod kinova_hold_roll;
mod kinova_pretrain;
mod kinova_step;
