//! # hil-kinova-mujoco
//!
//! A Kinova Gen3 feeding environment simulated in MuJoCo 3.17.
//!
//! - [`model`]: our own MJCF of the Gen3 6-DoF arm with the 2-DoF feeding
//!   fork (pitch β, roll γ, four tines), a table, a plate and food items.
//! - [`food`]: food kinds, randomised mechanical properties, published rates.
//! - [`skewer`]: the tine–food interaction model (indentation, puncture,
//!   cutting, grip, tearing) from which skewering success emerges.
//! - [`controller`]: differential inverse kinematics and the six skewering
//!   actions (VS/TV/TA × roll 0°/90°).
//! - [`sim`]: one simulated attempt from placement to hold.
//! - [`perception`]: what a camera reports and its embedding into contexts.
//! - [`env`]: [`KinovaFeedingEnv`], the `hil_core::Environment`, and its
//!   config type `kinova_feeding`.
//! - [`calibrate`]: success rates per (food, action) beside the published ones.
//!
//! Everything above needs the crate feature `physics`, which links
//! libmujoco: run `scripts/setup-mujoco` once to install MuJoCo into
//! `third_party/`, then build with `--features physics`. Without the
//! feature the crate only registers a `kinova_feeding` config whose build
//! fails with [`hil_core::HilError::Unsupported`] saying so, so that
//! `cargo test --workspace` passes with only the Rust toolchain.

#[cfg(feature = "physics")]
pub mod calibrate;
#[cfg(feature = "physics")]
pub mod controller;
#[cfg(feature = "physics")]
pub mod env;
#[cfg(feature = "physics")]
pub mod error;
#[cfg(feature = "physics")]
pub mod food;
#[cfg(feature = "physics")]
pub mod model;
#[cfg(feature = "physics")]
pub mod perception;
#[cfg(feature = "physics")]
pub mod render;
#[cfg(feature = "physics")]
pub mod sim;
#[cfg(feature = "physics")]
pub mod skewer;
#[cfg(not(feature = "physics"))]
mod without_physics;

#[cfg(feature = "physics")]
pub use controller::{ACTIONS, Action};

#[cfg(feature = "physics")]
pub use calibrate::{CalibrationOptions, CalibrationReport, CalibrationRow, calibrate};
#[cfg(feature = "physics")]
pub use env::{KinovaFeedingConfig, KinovaFeedingEnv};
#[cfg(feature = "physics")]
pub use error::KinovaError;
#[cfg(feature = "physics")]
pub use food::{FoodKind, FoodModel, FoodProps, Setting, Shape};
#[cfg(feature = "physics")]
pub use sim::{AttemptReport, Simulator};

/// Whether this build has the MuJoCo simulation (the `physics` feature).
pub const PHYSICS: bool = cfg!(feature = "physics");

/// How to get a build with the MuJoCo simulation: what a program built
/// without the `physics` feature tells its user.
pub const ENABLE_PHYSICS: &str = "it was built without the MuJoCo physics; run scripts/setup-mujoco, then build with `--features physics` (bash scripts/hil and scripts/test do both)";
