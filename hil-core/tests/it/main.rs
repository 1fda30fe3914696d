//! The integration tests of `hil-core`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod checkpoint_unsupported;
mod choices;
mod properties;
mod session_loop;
mod session_step;
