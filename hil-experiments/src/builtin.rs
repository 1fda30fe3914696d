//! Every built-in component type, in every program that uses this crate.
//!
//! typetag registers a config type (`type = "linucb"`) from the crate that
//! defines it, and a program holds that registration only if the crate is
//! linked into it. This crate names every built-in component crate below,
//! so any program that uses `hil_experiments` (the `hil` binary, a
//! downstream tool, a test) has them all: there is nothing to call. A
//! program that uses only `hil_core` has only the types of the crates it
//! names itself; [`load_experiment`] is the entry point that guarantees
//! the built-ins.
//!
//! ```
//! // A fresh program (each doctest is its own binary): no registration
//! // call, only this crate's entry point.
//! use hil_plugin::{ComponentKind, builtin_types};
//! let text = r#"
//! [environment]
//! type = "demo_plate"
//! foods = ["banana", "carrot"]
//! [policy]
//! type = "linucb_qg"
//! alpha = 0.5
//! w = 1.0
//! [workload]
//! type = "bundled"
//! name = "f12_sim"
//! [channel]
//! type = "simulated_expert"
//! "#;
//! let cfg = hil_experiments::parse_experiment(text, "inline.toml".as_ref()).unwrap();
//! assert_eq!(cfg.episodes, 1);
//! // Every built-in type of every kind is there.
//! let every = [
//!     (ComponentKind::Policy, &["always_query", "demo_learner", "linucb", "linucb_exp_decay", "linucb_qg"][..]),
//!     (ComponentKind::Environment, &["demo_plate", "food_replay", "kinova_feeding"]),
//!     (ComponentKind::WorkloadModel, &["bundled", "demo_counting", "model_file"]),
//!     (ComponentKind::QueryChannel, &["simulated_expert", "terminal", "web"]),
//! ];
//! for (kind, names) in every {
//!     assert_eq!(builtin_types(kind), names, "{kind}");
//! }
//! ```

use std::path::Path;

use crate::ExperimentConfig;
use hil_core::{ConfigError, Result};

// Naming each crate links it, and with it the types it registers.
use hil_channels as _;
use hil_envs as _;
use hil_kinova_mujoco as _;
use hil_policies as _;
use hil_workload as _;

/// Reads and validates an experiment file ([`ExperimentConfig::load`]) in
/// a program that holds every built-in component type.
pub fn load_experiment(path: &Path) -> Result<ExperimentConfig> {
    ExperimentConfig::load(path)
}

/// Parses experiment TOML ([`ExperimentConfig::parse`]) in a program that
/// holds every built-in component type; `path` names the file in errors.
pub fn parse_experiment(
    text: &str,
    path: &Path,
) -> std::result::Result<ExperimentConfig, ConfigError> {
    ExperimentConfig::parse(text, path)
}
