//! Conformance suites and property-test strategies for implementers.
//!
//! Like Gymnasium's `check_env`, every implementation of a hil trait (built
//! in or from a plugin) is run through the same suite:
//! [`check_policy`], [`check_environment`], [`check_workload_model`],
//! [`check_query_channel`]. Each returns a [`ConformanceReport`] listing what
//! was checked and what was skipped (e.g. checkpointing for a policy that
//! does not support it), or the first [`ConformanceFailure`].
//!
//! [`fixtures`] has small, real implementations of the traits for tests of
//! code that consumes them (session loop, logs, metrics; the channel to use
//! is the real [`crate::channel::PerfectExpert`]), and
//! [`strategies`] has proptest strategies (contexts, query histories,
//! positive-definite matrices), and [`cdylib`] builds plugin libraries
//! from tests.

pub mod cdylib;
pub mod fixtures;
pub mod mutate;
pub mod strategies;

mod channel;
mod environment;
mod policy;
mod workload;

pub use channel::check_query_channel;
pub use environment::check_environment;
pub use policy::check_policy;
pub use workload::check_workload_model;

/// A conformance check that failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("conformance check `{check}` failed for `{subject}`: {detail}")]
pub struct ConformanceFailure {
    /// The implementation under test.
    pub subject: String,
    /// The check that failed.
    pub check: &'static str,
    /// What was observed.
    pub detail: String,
}

/// What a conformance run covered.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConformanceReport {
    /// The implementation under test.
    pub subject: String,
    /// Checks that passed.
    pub passed: Vec<&'static str>,
    /// Checks that did not apply, with the reason.
    pub skipped: Vec<(&'static str, String)>,
}

pub(crate) struct Checker {
    report: ConformanceReport,
}

impl Checker {
    pub(crate) fn new(subject: &str) -> Self {
        Self {
            report: ConformanceReport {
                subject: subject.to_string(),
                ..Default::default()
            },
        }
    }

    pub(crate) fn check(
        &mut self,
        check: &'static str,
        ok: bool,
        detail: impl FnOnce() -> String,
    ) -> Result<(), ConformanceFailure> {
        if ok {
            if !self.report.passed.contains(&check) {
                self.report.passed.push(check);
            }
            Ok(())
        } else {
            Err(self.fail(check, detail()))
        }
    }

    pub(crate) fn fail(&self, check: &'static str, detail: String) -> ConformanceFailure {
        ConformanceFailure {
            subject: self.report.subject.clone(),
            check,
            detail,
        }
    }

    /// Unwraps `r`, turning an error into a failure of `check`.
    pub(crate) fn ok<T>(
        &self,
        check: &'static str,
        r: crate::Result<T>,
    ) -> Result<T, ConformanceFailure> {
        r.map_err(|e| self.fail(check, format!("unexpected error: {e}")))
    }

    pub(crate) fn skip(&mut self, check: &'static str, why: String) {
        self.report.skipped.push((check, why));
    }

    pub(crate) fn finish(self) -> ConformanceReport {
        self.report
    }
}

/// A seeded generator of random test contexts.
pub(crate) fn random_context(rng: &mut impl rand::Rng, dim: usize) -> crate::Context {
    let v: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    crate::Context::new(v).expect("finite by construction")
}
