//! Tests against the naive reference estimator ([`super::reference`],
//! private to the crate): the fast representations agree with it, and
//! LinUCB-QG's query gap behaves as the paper's argument needs.

mod agreement;
mod gap_monotonicity;
