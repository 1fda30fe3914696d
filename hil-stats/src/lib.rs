//! The one home of hil's statistics: every crate that summarises a sample,
//! tests a difference or corrects for many tests does it here.
//!
//! - [`summary`]: mean, population standard deviation and standard error
//!   ([`Stat`], [`mean_std`], [`standard_error`]);
//! - [`quantile`]: medians and nearest-rank quantiles;
//! - [`hypothesis`]: a test's alternative and result;
//! - [`rank`]: Mann-Whitney U and Wilcoxon signed-rank tests;
//! - [`fisher`]: Fisher's exact test of two success counts;
//! - [`binomial`]: binomial probabilities, tails, standard errors and the
//!   distribution of a sum of independent counts;
//! - [`correction`]: multiple-comparison corrections (Bonferroni).
//!
//! A leaf crate (it depends on no other hil crate) so that every layer,
//! `hil-core` included, can use one definition; a physics crate can test
//! its rates without depending on the workload crate. Normal tails and log
//! binomial coefficients come from `statrs`; the rest is written out where
//! the project's published results depend on the exact arithmetic (order of
//! summation, n against n − 1), which `statrs`'s streaming estimators do
//! not reproduce.

pub mod binomial;
pub mod correction;
mod error;
pub mod fisher;
pub mod hypothesis;
pub mod quantile;
pub mod rank;
pub mod summary;

pub use binomial::{binomial_pmf, binomial_se, binomial_upper_tail, convolve};
pub use correction::bonferroni;
pub use error::{Result, StatsError};
pub use fisher::fisher_exact;
pub use hypothesis::{Alternative, TestResult};
pub use quantile::{median, quantile};
pub use rank::{EXACT_LIMIT, mann_whitney_u, wilcoxon_signed_rank};
pub use summary::{Stat, mean, mean_std, standard_error};
