//! The integration tests of `hil-envs`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod env_and_dataset;
