//! # hil-experiments
//!
//! The paper's protocols as library code, so that the `hil` binary, downstream
//! crates and tests run the same experiments: the simulated testbed, the
//! user-study protocol, aggregation with uncertainty, tables and figures, and
//! the paper's published tables as data.
//!
//! - [`experiment_config`]: the experiment file, [`ExperimentConfig`]
//!   (components named by type, built-in or from the plugins it lists);
//!   [`experiment`]: the built [`Experiment`] run over its episodes;
//!   [`recorded`]: [`run_recorded`], the run with its interaction record,
//!   resumable from the log;
//! - [`builtin`]: every built-in component type is linked into any
//!   program using this crate; [`load_experiment`] reads a config with
//!   all of them, with no registration call;
//! - [`grids`]: the grid the paper's published f_q imply, and grid
//!   variants selected over the same runs;
//! - [`method`]: a method of either protocol (a labelled policy config,
//!   built-in or plugin, with an optional tuned hyperparameter);
//! - [`testbed`]: the paper's simulated-testbed protocol (methods as policy
//!   configs, runs in parallel, hyperparameters chosen on validation, the
//!   cross-data experiment);
//! - [`components`]: the testbed's pluggable parts (the query channel and
//!   environment of every episode; the paper's by default);
//! - [`user_study`]: the paper's real-robot user-study protocol (methods
//!   in counterbalanced order, per-plate results, mean ± standard error)
//!   on any environment, and over many seeds; its default scene is the
//!   MuJoCo simulation, which needs the crate feature `physics` (run
//!   `scripts/setup-mujoco` first), as do its keyframes;
//! - [`run`]: running an experiment file with its interaction record, and
//!   resuming one from its log (what `hil run` and hil-py's `hil.run` do);
//! - [`docs`]: EXPERIMENTS.md written from a run's results;
//! - [`results`]: selection and aggregation; [`report`]: Markdown tables
//!   beside the paper's published numbers ([`published`], read from data
//!   files); [`plot`]: SVG figures; [`output`]: writes them all.
//!
//! Results computed from hil's bundled data are **synthetic, calibrated to
//! published figures**: they are not the paper's results, and every table and
//! figure says so.

pub mod bench;
pub mod builtin;
pub mod calibrate;
pub mod claims;
pub mod components;
pub mod docs;
pub mod experiment;
pub mod experiment_config;
pub mod grids;
pub mod method;
pub mod output;
pub mod plot;
pub mod published;
pub mod recorded;
pub mod report;
pub mod results;
pub mod results_page;
pub mod run;
pub mod testbed;
pub mod user_study;

pub use builtin::{load_experiment, parse_experiment};
pub use experiment::{Experiment, ExperimentSummary};
pub use experiment_config::{ExperimentConfig, load_plugins};
pub use method::Method;
pub use recorded::run_recorded;
pub use testbed::{NamedModel, Protocol, ProtocolSettings};
pub use user_study::{UserStudy, UserStudyConfig, UserStudyResult};
