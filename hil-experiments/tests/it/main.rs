//! The integration tests of `hil-experiments`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

#[path = "../../../tests/support/demo.rs"]
mod demo;
#[path = "../../../tests/support/study.rs"]
mod study;

mod experiment_config;
mod protocol_components;
mod record;
mod record_fuzz;
mod record_keyed;
mod run_flow;
mod session_checks;
mod testbed;
mod user_study;
mod user_study_over_seeds;
mod user_study_plugins;
mod user_study_selection;
mod user_study_where_asked;
