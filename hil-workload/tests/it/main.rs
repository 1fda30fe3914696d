//! The integration tests of `hil-workload`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod configs;
mod data_and_selection;
mod generator_centre;
mod model_fuzz;
mod models;
mod solver_vs_clarabel;
mod study_fuzz;
