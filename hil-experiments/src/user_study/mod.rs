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
//! pretraining_trials = 2
//! [workload]
//! type = "bundled"
//! name = "f12_real"
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
//! policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, w = 0.3, pretrain = true }
//! ```
//!
//! Run it with [`UserStudyConfig::run`], or, to observe or wrap the
//! environment per plate (e.g. to render keyframes), build the environment,
//! [`UserStudyConfig::prepare`] the methods and call [`UserStudy::run_with`].

mod config;
mod run;

pub use config::{PAPER_N_ATT, UserStudyConfig};
pub use run::{
    Episode, MeanSem, MethodSummary, Plate, PlateResult, Protocol, UserStudy, UserStudyResult,
    mean_sem, method_order,
};
