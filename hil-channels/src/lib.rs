//! # hil-channels
//!
//! How a query reaches a person and comes back, for **hil**:
//!
//! - [`SimulatedExpert`]: the paper's perfect expert (with default
//!   parameters; the bare perfect expert is `hil_core::channel::PerfectExpert`),
//!   or an imperfect one with an error rate, a decline rate and a
//!   response-time model (`type = "simulated_expert"`).
//! - [`TerminalChannel`]: an interactive prompt for researchers at a
//!   terminal (`type = "terminal"`).
//! - [`WebChannel`]: a page served on 127.0.0.1 for the person being fed,
//!   on a phone or tablet, by touch, keyboard or single switch
//!   (`type = "web"`).
//! - [`study`]: the paper's querying-workload study served on the same
//!   server (`hil study serve`), with fsync'ed, resumable participant logs
//!   and an export to the study CSV that `hil_workload` fits models from.
//!
//! To try the channels without a robot, the demo components live with
//! their traits: `hil_envs::demo_plate` (`demo_plate`),
//! `hil_policies::demo_learner` (`demo_learner`) and
//! `hil_workload::demo_counting` (`demo_counting`).
//!
//! Every channel passes `hil_conformance::check_query_channel` (the human
//! ones with a scripted person at the other end, in their tests).

pub mod present;
pub mod simulated;
pub mod study;
pub mod terminal;
pub mod web;

// The HTTP server's unit tests (web::http) use the integration tests'
// helpers, which name this crate by its name.
#[cfg(test)]
extern crate self as hil_channels;
#[cfg(test)]
#[path = "../tests/it/web_support/mod.rs"]
mod web_support;

pub use simulated::{ResponseTimeModel, SimulatedExpert, SimulatedExpertConfig};
pub use terminal::{TerminalChannel, TerminalChannelConfig};
pub use web::{WebChannel, WebChannelConfig};
