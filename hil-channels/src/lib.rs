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
//!
//! The web page is served by `hil-http`, the small server the browser
//! workload study (`hil-study`, `hil study serve`) uses too.
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
pub mod terminal;
pub mod web;

pub use simulated::{ResponseTimeModel, SimulatedExpert, SimulatedExpertConfig};
pub use terminal::{TerminalChannel, TerminalChannelConfig};
pub use web::{WebChannel, WebChannelConfig};
