//! The integration tests of `hil-envs`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod dataset_fuzz;
mod env_and_dataset;
