//! # hil-kinova-mujoco
//!
//! A Kinova Gen3 feeding environment simulated in MuJoCo 3.17.
//!
//! The public interface is the environment and the tools around it:
//!
//! - [`KinovaFeedingEnv`], the `hil_core::Environment`, and its config
//!   type `kinova_feeding` ([`KinovaFeedingConfig`]);
//!   [`KinovaFeedingEnv::from_component`] finds the concrete scene behind
//!   any environment config;
//! - [`calibrate`] / [`calibrate_with`]: success rates per (food, action)
//!   beside the published ones; [`AttemptLog`]: every attempt as JSON
//!   lines;
//! - [`Simulator`]: one simulated attempt from placement to hold
//!   ([`Placement`], [`PerceivedTarget`], [`AttemptReport`]), on our own
//!   MJCF of the Gen3 6-DoF arm with the 2-DoF feeding fork or on a scene
//!   given as [`MjcfSource`];
//! - the six skewering actions ([`actions`]), food kinds and placement
//!   settings ([`FoodKind`], [`Setting`]);
//! - [`KeyframeWriter`] / [`RenderingEnv`]: PNG keyframes of attempts.
//!
//! Inside (private): the MJCF model, the tine–food interaction model
//! (indentation, puncture, cutting, grip, tearing) from which skewering
//! success emerges, differential inverse kinematics, and simulated
//! perception with its embedding into contexts.
//!
//! Everything above needs the crate feature `physics`, which links
//! libmujoco: run `scripts/setup-mujoco` once to install MuJoCo into
//! `third_party/`, then build with `--features physics`. Without the
//! feature the crate only registers a `kinova_feeding` config whose build
//! fails with [`hil_core::HilError::Unsupported`] saying so, so that
//! `cargo test --workspace` passes with only the Rust toolchain.

#[cfg(feature = "physics")]
mod attempt_log;
#[cfg(feature = "physics")]
mod calibrate;
#[cfg(feature = "physics")]
pub mod calibration_text;
#[cfg(feature = "physics")]
mod controller;
#[cfg(feature = "physics")]
mod env;
#[cfg(feature = "physics")]
mod error;
#[cfg(feature = "physics")]
mod food;
#[cfg(feature = "physics")]
mod food_models;
#[cfg(feature = "physics")]
mod model;
#[cfg(feature = "physics")]
mod perception;
#[cfg(feature = "physics")]
mod render;
#[cfg(feature = "physics")]
mod sim;
#[cfg(feature = "physics")]
mod skewer;
#[cfg(not(feature = "physics"))]
mod without_physics;

#[cfg(feature = "physics")]
pub use attempt_log::AttemptLog;
#[cfg(feature = "physics")]
pub use calibrate::{
    AttemptRecord, CalibrationOptions, CalibrationOverSeeds, CalibrationReport, CalibrationRow,
    CalibrationTarget, CellP, Consistency, FoodModelsUsed, SettingCell, TARGET_GRID, Tally,
    calibrate, calibrate_over_seeds, calibrate_with, expected_abs_error_of_a_perfect_simulator,
};
#[cfg(feature = "physics")]
pub use controller::{Action, PitchFamily, RollBy, actions};
#[cfg(feature = "physics")]
pub use env::{
    KinovaFeedingConfig, KinovaFeedingEnv, MAX_PRETRAINING_TRIALS, simulated_pretraining,
};
#[cfg(feature = "physics")]
pub use error::KinovaError;
#[cfg(feature = "physics")]
pub use food::{FoodKind, FoodModel, FoodProps, Label, Setting, Shape, parse_labels};
#[cfg(feature = "physics")]
pub use food_models::FoodModels;
#[cfg(feature = "physics")]
pub use model::MjcfSource;
#[cfg(feature = "physics")]
pub use render::{Keyframe, KeyframeRecorder, KeyframeWriter, RenderingEnv, View};
#[cfg(feature = "physics")]
pub use sim::{
    AttemptReport, FREE_DT, MIN_TINES_TOUCHED, PerceivedTarget, Placement, Simulator, StopReason,
};
#[cfg(feature = "physics")]
pub use skewer::{MAX_DT, REF_DT};

/// Whether this build has the MuJoCo simulation (the `physics` feature).
pub const PHYSICS: bool = cfg!(feature = "physics");

/// How to get a build with the MuJoCo simulation: what a program built
/// without the `physics` feature tells its user.
pub const ENABLE_PHYSICS: &str = "it was built without the MuJoCo physics; run scripts/setup-mujoco, then build with `--features physics` (bash scripts/hil and scripts/test do both)";
