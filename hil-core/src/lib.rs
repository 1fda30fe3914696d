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
//! - Size-limited file reading ([`files`]) and [`ConfigError`], the located
//!   error every config loader returns.
//!
//! Everything else has its own crate, each depending on this one:
//! `hil-config` (component configs, build contexts, the limits every count
//! is checked against, TOML error location),
//! `hil-plugin` (plugins loaded from shared libraries, `declare_plugin!`),
//! `hil-conformance` (the conformance suites for implementers),
//! `hil-textdata` (CSV and line-table readers),
//! `hil-record` (the interaction record: every step logged durably under a
//! hash chain, keyed when it must resist forgery, and resumed after a kill).
#![deny(unsafe_code)]

pub mod action;
pub mod channel;
pub mod context;
pub mod decision;
pub mod environment;
pub mod error;
pub mod event;
pub mod files;
pub mod metrics;
pub mod policy;
pub mod query;
pub mod secrets;
pub mod session;
pub mod time;
pub mod workload;

pub use action::{ActionSpace, ArmId};
pub use channel::{PerfectExpert, QueryChannel};
pub use context::{Context, Item};
pub use decision::{
    ArmDiagnostics, Choice, Decision, Diagnostics, Extras, LabelledObservation, Outcome,
};
pub use environment::{CallOrder, Environment};
pub use error::{BoxError, ConfigError, HilError, Result};
pub use event::{PendingStep, StepDecision, StepEvent};
pub use metrics::EpisodeMetrics;
pub use policy::{Attempt, DecisionInput, Feedback, Policy};
pub use query::{
    Answer, BoundingBox, Difficulty, Distraction, Query, QueryKind, Response, ResponseType,
};
pub use session::{
    Episode, EpisodeReport, EventCollector, Session, SessionObserver, SessionSettings,
};
pub use time::{TimeGrid, Timestep};
pub use workload::{
    QueryHistory, QueryRecord, WorkloadForecast, WorkloadInput, WorkloadModel, WorkloadTracker,
};

/// The version of this crate, which a plugin's handshake compares with the
/// host's (`hil_plugin::BuildFacts`).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
