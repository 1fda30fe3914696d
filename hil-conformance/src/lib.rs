//! # hil-conformance
//!
//! Conformance suites and property-test strategies for implementers of
//! hil's four traits: one suite per trait, a deliberately broken twin per
//! check ([`broken`]), [`conformance_tests!`], fixtures and proptest
//! strategies.
//!
//! Like Gymnasium's `check_env`, every implementation of a hil trait (built
//! in or from a plugin) is run through the same suite:
//! [`check_policy`], [`check_environment`], [`check_workload_model`],
//! [`check_query_channel`] (and their `_with` forms taking [`CheckOptions`]).
//! Each returns a [`ConformanceReport`] listing what was checked and what was
//! skipped (only checkpointing, for a policy whose fresh instance says it
//! cannot), or the first [`ConformanceFailure`], which names the [`Check`],
//! what was observed, and the likely cause and fix.
//!
//! The suites are strict: a refusal must be the error kind the contract
//! names (a dimension mismatch, an arm out of range, a call out of order),
//! and a panic (which a plugin's guard turns into [`HilError::Plugin`]) is a
//! failure, never a refusal, whose hint is about the method that panicked
//! ([`ConformanceFailure::panicked_in`]). Every suite drives one long
//! trajectory ([`CheckOptions::with_steps`], 300 steps by default), so a
//! component that fails on its 50th call fails, and every factory-driven
//! suite checks that no object it built panics when dropped
//! ([`Check::Destructor`]). [`crate::conformance_tests!`] expands into one
//! `#[test]` per property, so a failing test names the property;
//! [`broken`] holds a deliberately broken implementation for every check.
//!
//! [`fixtures`] has small, real implementations of the traits for tests of
//! code that consumes them (session loop, logs, metrics; the channel to use
//! is the real [`hil_core::channel::PerfectExpert`]), and
//! [`strategies`] has proptest strategies (contexts, query histories,
//! positive-definite matrices), and [`cdylib`] builds plugin libraries
//! from tests.

/// The two public entry points of a factory-driven suite: every property
/// (`$with`), or one (`$only`), both through [`run_suite`] with the
/// module's `suite` function.
macro_rules! entry_points {
    ($trait:ident, $(#[$with_doc:meta])* $with:ident, $(#[$only_doc:meta])* $only:ident $(,)?) => {
        $(#[$with_doc])*
        pub fn $with(
            make: &dyn Fn() -> hil_core::Result<Box<dyn hil_core::$trait>>,
            opts: &$crate::CheckOptions,
        ) -> Result<$crate::ConformanceReport, $crate::ConformanceFailure> {
            $crate::run_suite(make, opts, None, suite)
        }

        $(#[$only_doc])*
        pub fn $only(
            make: &dyn Fn() -> hil_core::Result<Box<dyn hil_core::$trait>>,
            opts: &$crate::CheckOptions,
            property: $crate::Check,
        ) -> Result<$crate::ConformanceReport, $crate::ConformanceFailure> {
            $crate::run_suite(make, opts, Some(property), suite)
        }
    };
}

pub mod broken;
pub mod cdylib;
pub mod fixtures;
pub mod mutate;
pub mod strategies;

mod channel;
mod check;
mod environment;
mod generated;
mod options;
mod policy;
mod workload;

pub use channel::{check_query_channel, check_query_channel_only, check_query_channel_with};
pub use check::{Check, Subject};
pub use environment::{check_environment, check_environment_only, check_environment_with};
pub use generated::assert_conforms;
pub use options::{CheckOptions, MAX_CHECK_STEPS};
pub use policy::{check_policy, check_policy_only, check_policy_with};
pub use workload::{
    check_workload_model, check_workload_model_built_only, check_workload_model_built_with,
    check_workload_model_only, check_workload_model_with,
};

use hil_core::HilError;

/// hil-core, for the paths [`conformance_tests!`] expands to (so a crate
/// using the macro needs no `hil_core` import of its own).
#[doc(hidden)]
pub use hil_core as __core;

/// A conformance check that failed.
///
/// Match on [`ConformanceFailure::check`] (and
/// [`ConformanceFailure::panicked_in`]); the message adds what was observed
/// and [`ConformanceFailure::hint`] (the likely cause and the fix).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("conformance check `{check}` failed for `{subject}`: {detail}\n  likely cause and fix: {}", self.hint())]
pub struct ConformanceFailure {
    /// The implementation under test.
    pub subject: String,
    /// The check that failed.
    pub check: Check,
    /// What was observed.
    pub detail: String,
    /// The method whose panic caused the failure (as the panic guard names
    /// it: `decide`, `seed`, `drop`, `factory`, ...), if a panic did.
    pub panicked_in: Option<String>,
}

impl ConformanceFailure {
    /// The likely cause and fix: the check's [`Check::hint`], or, when a
    /// panic caused the failure and the check's hint is not about panics,
    /// what to do about a panic in that method.
    pub fn hint(&self) -> String {
        match &self.panicked_in {
            Some(method) if !self.check.hint_covers_panics() => check::panic_hint(method),
            _ => self.check.hint().to_string(),
        }
    }
}

/// What a conformance run covered.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConformanceReport {
    /// The implementation under test.
    pub subject: String,
    /// Checks that passed.
    pub passed: Vec<Check>,
    /// Checks that did not apply, with the reason.
    pub skipped: Vec<(Check, String)>,
}

impl ConformanceReport {
    /// The names of the checks that passed, comma-separated.
    pub fn passed_names(&self) -> String {
        self.passed
            .iter()
            .map(|c| c.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Records the outcome of the checks of one run. When the run is limited
/// to one property (`only`), every other non-prerequisite check is neither
/// enforced nor recorded, and scenarios skip the calls only they need.
pub(crate) struct Checker {
    report: ConformanceReport,
    only: Option<Check>,
}

impl Checker {
    pub(crate) fn new(subject: &str, only: Option<Check>) -> Self {
        Self {
            report: ConformanceReport {
                subject: subject.to_string(),
                ..Default::default()
            },
            only,
        }
    }

    /// Whether `check` is part of this run.
    pub(crate) fn wants(&self, check: Check) -> bool {
        check.is_prerequisite() || self.only.is_none_or(|o| o == check)
    }

    /// Whether any of `checks` is part of this run.
    pub(crate) fn wants_any(&self, checks: &[Check]) -> bool {
        checks.iter().any(|&c| self.wants(c))
    }

    pub(crate) fn check(
        &mut self,
        check: Check,
        ok: bool,
        detail: impl FnOnce() -> String,
    ) -> Result<(), ConformanceFailure> {
        if !self.wants(check) {
            return Ok(());
        }
        if ok {
            if !self.report.passed.contains(&check) {
                self.report.passed.push(check);
            }
            Ok(())
        } else {
            Err(self.fail(check, detail()))
        }
    }

    pub(crate) fn fail(&self, check: Check, detail: String) -> ConformanceFailure {
        ConformanceFailure {
            subject: self.report.subject.clone(),
            check,
            detail,
            panicked_in: None,
        }
    }

    /// A failure of `check` caused by the error `e` (a guarded panic's
    /// method is kept, so the hint is about the panic).
    pub(crate) fn fail_with(
        &self,
        check: Check,
        detail: String,
        e: &HilError,
    ) -> ConformanceFailure {
        ConformanceFailure {
            panicked_in: hil_plugin::panicked_in(e),
            ..self.fail(check, detail)
        }
    }

    /// Unwraps `r`, turning an error into a failure of `check`. A guarded
    /// panic ([`HilError::Plugin`]) is called a panic, so it is never
    /// mistaken for a refusal.
    pub(crate) fn ok<T>(
        &self,
        check: Check,
        r: hil_core::Result<T>,
    ) -> Result<T, ConformanceFailure> {
        r.map_err(|e| self.fail_with(check, describe_error(&e), &e))
    }

    /// Checks that `r` is an error for which `expected` holds; `call` says
    /// what was called with what, `kind` names the expected variant.
    pub(crate) fn refused<T: std::fmt::Debug>(
        &mut self,
        check: Check,
        call: &str,
        kind: &str,
        r: hil_core::Result<T>,
        expected: impl FnOnce(&HilError) -> bool,
    ) -> Result<(), ConformanceFailure> {
        if !self.wants(check) {
            return Ok(());
        }
        let detail = match &r {
            Err(e) if expected(e) => return self.check(check, true, String::new),
            Ok(v) => format!("{call} was accepted (returned {v:?}); expected {kind}"),
            Err(e @ HilError::Plugin { .. }) => {
                let detail = format!("{call} panicked instead of returning {kind}: {e}");
                return Err(self.fail_with(check, detail, e));
            }
            Err(e) => format!("{call} returned the wrong error: {e:?}; expected {kind}"),
        };
        Err(self.fail(check, detail))
    }

    pub(crate) fn skip(&mut self, check: Check, why: String) {
        if self.wants(check) {
            self.report.skipped.push((check, why));
        }
    }

    pub(crate) fn finish(self) -> ConformanceReport {
        self.report
    }
}

/// Where the panic guard says an object under test came from.
fn under_test() -> std::path::PathBuf {
    std::path::PathBuf::from("<object under test>")
}

/// A kind of object a factory-driven suite checks (policy, query channel,
/// environment): what its factory is called in a failure, and how one
/// instance goes under the plugin panic guard.
pub(crate) trait UnderTest {
    /// The factory's name in a [`Check::Build`] failure (e.g. `policy`).
    const WHAT: &'static str;
    /// The object's own name, which the report names.
    fn subject_name(&self) -> &str;
    /// `self` under the plugin panic guard (again, for a plugin's).
    fn guard(self: Box<Self>) -> hil_core::Result<Box<Self>>;
}

macro_rules! under_test {
    ($($tr:ident => $guard:ident, $what:literal;)*) => {$(
        impl UnderTest for dyn hil_core::$tr {
            const WHAT: &'static str = $what;
            fn subject_name(&self) -> &str {
                self.name()
            }
            fn guard(self: Box<Self>) -> hil_core::Result<Box<Self>> {
                let name = self.name().to_string();
                Ok(Box::new(hil_plugin::$guard::new(self, under_test(), &name)?))
            }
        }
    )*};
}

under_test! {
    Policy => GuardedPolicy, "policy";
    QueryChannel => GuardedChannel, "query channel";
    Environment => GuardedEnvironment, "environment";
    WorkloadModel => GuardedWorkload, "workload model";
}

/// How every factory-driven suite runs: `make`'s objects come under the
/// plugin panic guard, so a panic in a method is reported as a failure of
/// the check that called it instead of unwinding through the suite; the
/// options are validated and a first instance is built (a failure of
/// either is a [`Check::Build`] failure of the factory); the checker
/// reports under that instance's name and runs `only` check, or all.
/// Then `suite` runs, and once it has dropped every object it built,
/// [`Check::Destructor`] fails if any of them panicked in its destructor.
pub(crate) fn run_suite<'m, T: UnderTest + ?Sized>(
    make: &'m dyn Fn() -> hil_core::Result<Box<T>>,
    opts: &CheckOptions,
    only: Option<Check>,
    suite: impl FnOnce(Started<'m, T>, &CheckOptions) -> SuiteResult,
) -> SuiteResult {
    // Destructor panics left on this thread by earlier work are not ours.
    drop(hil_plugin::take_destructor_panics_on_this_thread());
    let result = start(make, opts, only).and_then(|s| suite(s, opts));
    let panics = hil_plugin::take_destructor_panics_on_this_thread();
    let report = result?;
    destructor_check(report, only, &panics)
}

/// [`Check::Destructor`] over the destructor panics of a run that
/// otherwise passed: one failure for all of them, naming how many objects
/// panicked and showing the first panic (with its location and backtrace)
/// once.
pub(crate) fn destructor_check(
    mut report: ConformanceReport,
    only: Option<Check>,
    panics: &[HilError],
) -> Result<ConformanceReport, ConformanceFailure> {
    if only.is_some_and(|o| o != Check::Destructor) {
        return Ok(report);
    }
    let Some(first) = panics.first() else {
        report.passed.push(Check::Destructor);
        return Ok(report);
    };
    let n = panics.len();
    Err(ConformanceFailure {
        subject: report.subject,
        check: Check::Destructor,
        detail: format!(
            "{n} object{} the suite built panicked when dropped; the first: {first}",
            if n == 1 { "" } else { "s" }
        ),
        panicked_in: Some("drop".into()),
    })
}

/// What a suite returns.
pub(crate) type SuiteResult = Result<ConformanceReport, ConformanceFailure>;

/// A factory of guarded objects under test.
pub(crate) type MakeGuarded<'m, T> = Box<dyn Fn() -> hil_core::Result<Box<T>> + 'm>;

/// A factory-driven suite, started: see [`run_suite`].
pub(crate) struct Started<'m, T: ?Sized> {
    /// Builds a fresh guarded instance.
    pub make: MakeGuarded<'m, T>,
    /// The first instance, already built.
    pub first: Box<T>,
    /// Reports under the first instance's name.
    pub checker: Checker,
}

fn start<'m, T: UnderTest + ?Sized>(
    make: &'m dyn Fn() -> hil_core::Result<Box<T>>,
    opts: &CheckOptions,
    only: Option<Check>,
) -> Result<Started<'m, T>, ConformanceFailure> {
    let make: MakeGuarded<'m, T> = Box::new(move || make()?.guard());
    let build_failure = |e: HilError| ConformanceFailure::of_factory(T::WHAT, &e);
    opts.validate().map_err(build_failure)?;
    let first = make().map_err(build_failure)?;
    let checker = Checker::new(first.subject_name(), only);
    Ok(Started {
        make,
        first,
        checker,
    })
}

impl ConformanceFailure {
    /// A [`Check::Build`] failure: the factory of a `what` (e.g. `policy`)
    /// under test, or the options it was given, failed before any object
    /// could be checked.
    pub fn of_factory(what: &str, e: &HilError) -> Self {
        Self {
            subject: format!("<{what} factory>"),
            check: Check::Build,
            detail: e.to_string(),
            panicked_in: hil_plugin::panicked_in(e),
        }
    }
}

/// An error as a failure's detail: a guarded panic is named as one.
fn describe_error(e: &HilError) -> String {
    match e {
        HilError::Plugin { .. } => format!("it panicked (the plugin guard reported: {e})"),
        _ => format!("unexpected error: {e}"),
    }
}

/// The `i`-th query kind of a suite's sequence: every response type,
/// difficulty and distraction in turn, each of the 18 kinds once per 18.
pub(crate) fn query_kind(i: usize) -> hil_core::QueryKind {
    use hil_core::{Difficulty, Distraction, ResponseType};
    hil_core::QueryKind {
        response: ResponseType::ALL[i % 3],
        difficulty: Difficulty::ALL[(i / 3) % 2],
        distraction: Distraction::ALL[(i / 6) % 3],
    }
}

/// A seeded generator of random test contexts.
pub(crate) fn random_context(rng: &mut impl rand::Rng, dim: usize) -> hil_core::Context {
    let v: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    hil_core::Context::new(v).expect("finite by construction")
}
