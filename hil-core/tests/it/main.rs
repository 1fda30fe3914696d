//! The integration tests of `hil-core`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod checkpoint_unsupported;
mod config;
mod conformance_catches;
mod properties;
mod record;
mod record_fuzz;
mod session_checks;
mod session_loop;
