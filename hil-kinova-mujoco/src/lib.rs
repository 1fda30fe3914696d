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
//! Run `scripts/setup-mujoco` once to install MuJoCo into `third_party/`.

pub mod calibrate;
pub mod controller;
pub mod env;
pub mod error;
pub mod food;
pub mod model;
pub mod perception;
pub mod render;
pub mod sim;
pub mod skewer;

pub use controller::{ACTIONS, Action};

pub use calibrate::{CalibrationOptions, CalibrationReport, CalibrationRow, calibrate};
pub use env::{KinovaFeedingConfig, KinovaFeedingEnv};
pub use error::KinovaError;
pub use food::{FoodKind, FoodModel, FoodProps, Setting, Shape};
pub use sim::{AttemptReport, Simulator};

/// Does nothing; calling it keeps this crate (and its typetag registrations)
/// linked into a binary that names its components only in configs.
pub fn link() {}
