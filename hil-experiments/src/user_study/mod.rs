//! The paper's real-robot user study as a protocol: one participant, one
//! plate of foods per session, every method met `repetitions` times in a
//! counterbalanced order, N_att attempts per item; per plate r_task_avg,
//! items fed and queries asked, and per method their mean ± standard error.
//!
//! A study file ([`UserStudyConfig`]) reads like an experiment file with
//! several methods; `examples/configs/user-study.toml` is the paper's
//! protocol ([`UserStudyConfig::paper`]) written out:
//!
//! ```toml
//! plugins = []              # loaded before the rest is read
//! seed = 7
//! repetitions = 2
//! [session]
//! n_att = 3
//! wl0 = 0.5
//! [environment]             # built once, shared by every plate
//! type = "kinova_feeding"
//! pretraining_trials = 10
//! pretrain_foods = ["honeydew", "kiwi", "celery"]   # off the plate
//! settings = ["isolated"]
//! neighbours = false
//! [workload]
//! type = "bundled"
//! name = "f12_sim"
//! [channel]                 # who answers; a fresh one for every plate
//! type = "simulated_expert"
//! [[methods]]
//! label = "LinUCB"
//! policy = { type = "linucb", alpha = 0.5, lambda = 1.0, pretrain = true }
//! [[methods]]
//! label = "AlwaysQuery"
//! policy = { type = "always_query", alpha = 0.5, lambda = 1.0, pretrain = true }
//! [[methods]]
//! label = "LinUCB-QG"
//! policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, w = 1.0, pretrain = true }
//! tune = { w = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0] }
//! [validation]              # chooses tuned values: highest mean M_wt(w_task)
//! plates = 4
//! w_task = 0.7
//! ```
//!
//! Run it with [`UserStudyConfig::run`] on any environment (the default,
//! the MuJoCo scene, needs the crate feature `physics`; a build without it
//! refuses a file that names no `[environment]`; [`UserStudyConfig::paper_on`]
//! is the paper's protocol on another environment), over many seeds in
//! parallel with [`UserStudyConfig::run_over_seeds`], with PNG keyframes
//! with `UserStudyConfig::run_pictured` (feature `physics`), or, to observe
//! or wrap the environment per plate, build the environment,
//! [`UserStudyConfig::prepare`] the methods and call [`UserStudy::run_with`].

mod config;
#[cfg(feature = "physics")]
mod keyframes;
mod reference;
mod run;
mod seeds;
pub mod text;

pub use config::{PAPER_WORKLOAD, UserStudyConfig, Validation};
#[cfg(feature = "physics")]
pub use keyframes::{Keyframes, PicturedStudy};
pub use reference::{PlateExpectation, PublishedReference, expected_plate};
pub use run::{
    Episode, MethodSummary, Plate, PlateResult, Protocol, Selection, UserStudy, UserStudyResult,
    method_order,
};
pub use seeds::{
    ChosenAcrossSeeds, MethodAcrossSeeds, PairedDifference, UserStudyOverSeeds, across_seeds,
    paired_differences,
};
