//! Tests of the crate's private parts (the `.npy` reader and writer).

mod dataset_fuzz;
mod loader_errors;
