//! # hil-core
//!
//! The vocabulary and the session loop of **hil**, a toolkit for
//! human-in-the-loop contextual bandits in assistive robotics: a robot picks
//! an action for each context (a food item on a plate) or asks the person it
//! serves, trading task success against the workload that asking imposes.
//!
//! - Vocabulary: [`Context`], [`ActionSpace`]/[`ArmId`], [`Decision`] and
//!   [`Choice`], [`QueryKind`], [`Query`], [`Response`], [`Outcome`],
//!   [`Timestep`]/[`TimeGrid`].
//! - The four traits: [`Policy`], [`WorkloadModel`], [`QueryChannel`],
//!   [`Environment`]; object-safe, so they can be named in configs and
//!   cross plugin boundaries. [`CallOrder`] is the environments' shared
//!   call-order check; [`PerfectExpert`] is the paper's perfect expert.
//! - The loop: [`Session`] runs episodes with the paper's semantics and
//!   emits one [`StepEvent`] per step; [`EpisodeMetrics`] computes the
//!   paper's metrics from those events.
//! - The interaction record: [`record`] logs every step durably and
//!   resumes killed sessions.
//! - Configs: [`config::ExperimentConfig`], with errors naming file, line and field.
//! - Plugins: [`plugin`] loads types from shared libraries ([`declare_plugin!`]).
//! - Conformance suites for implementers: `hil_core::testing` (feature `testing`).
// Only the plugin loader may use `unsafe` (it allows it locally).
#![deny(unsafe_code)]

pub mod action;
pub mod channel;
pub mod config;
pub mod context;
pub mod decision;
pub mod environment;
pub mod error;
pub mod experiment;
pub mod files;
pub mod metrics;
pub mod plugin;
pub mod policy;
pub mod query;
pub mod record;
pub mod session;
pub mod textdata;
pub mod time;
pub mod workload;

#[cfg(feature = "testing")]
pub mod testing;

pub use action::{ActionSpace, ArmId};
pub use channel::{PerfectExpert, QueryChannel};
pub use config::{BuildContext, BuildMemo, ConfigError, ExperimentConfig, TaskContext};
pub use context::Context;
pub use decision::{
    ArmDiagnostics, Choice, Decision, Diagnostics, Extras, LabelledObservation, Outcome,
};
pub use environment::{CallOrder, Environment, Item};
pub use error::{BoxError, HilError, Result};
pub use experiment::{Experiment, ExperimentSummary};
pub use metrics::EpisodeMetrics;
pub use policy::{DecisionInput, Feedback, Policy};
pub use query::{
    Answer, BoundingBox, Difficulty, Distraction, Query, QueryKind, Response, ResponseType,
};
pub use session::{
    EpisodeReport, EventCollector, PendingStep, Session, SessionObserver, SessionSettings,
    StepDecision, StepEvent,
};
pub use time::{TimeGrid, Timestep};
pub use workload::{
    QueryHistory, QueryRecord, WorkloadForecast, WorkloadInput, WorkloadModel, WorkloadTracker,
};
