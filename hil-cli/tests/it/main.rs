//! The integration tests of `hil-cli`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod common;
#[path = "../../../tests/support/demo.rs"]
mod demo;
#[path = "../../../tests/support/study.rs"]
mod study;

mod bench;
mod cli;
mod closed_pipes;
mod count_limits;
mod data_inputs;
#[cfg(feature = "physics")]
mod kinova;
#[cfg(feature = "physics")]
mod kinova_seeds;
mod record_cmd;
mod reproduce;
mod resume;
mod run_reliability;
#[cfg(feature = "speech")]
mod speech_interrupt;
mod study_resume;
mod terminal_pty;
mod web_run;
#[cfg(not(feature = "physics"))]
mod without_physics;
#[cfg(not(feature = "speech"))]
mod without_speech;
mod workload_seeds;
