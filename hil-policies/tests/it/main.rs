//! The integration tests of `hil-policies`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod config;
mod conformance;
mod session;
