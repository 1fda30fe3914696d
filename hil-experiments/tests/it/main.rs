//! The integration tests of `hil-experiments`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod testbed;
mod user_study;
mod user_study_plugins;
mod user_study_selection;
