use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use super::strategies::query_history;
use super::{Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport};
use hil_core::{QueryHistory, QueryKind, WorkloadInput, WorkloadModel};

/// Runs the workload-model conformance suite; see
/// [`check_workload_model_with`] for the checks.
pub fn check_workload_model(
    model: &dyn WorkloadModel,
) -> Result<ConformanceReport, ConformanceFailure> {
    check_workload_model_with(model, &CheckOptions::default())
}

/// Runs every workload-model property, stopping at the first failure.
///
/// Over WL_0 in {0, 0.25, 0.5, 0.75, 1} and 200 random histories:
/// [`Check::EmptyHistory`] (an empty history at t = 0 gives a finite
/// value), [`Check::FinitePrediction`], [`Check::DeterministicPrediction`]
/// (repeated calls agree to the bit) and [`Check::Counterfactual`]
/// (`predict_if_queried` equals `predict` on the history with the query
/// appended); then, over a long trajectory (a history growing by one query
/// per step to `opts.steps()` queries, 300 by default, beyond any plausible
/// buffer), that `predict` succeeds and is finite at every step.
///
/// The model is only borrowed, so [`Check::Destructor`] is not run: the
/// factory forms ([`check_workload_model_built_with`]) build, check and
/// drop their own instance.
pub fn check_workload_model_with(
    model: &dyn WorkloadModel,
    opts: &CheckOptions,
) -> Result<ConformanceReport, ConformanceFailure> {
    run(model, opts, Checker::new(model.name(), None))
}

/// Runs one workload-model property alone (see [`check_workload_model_with`]).
pub fn check_workload_model_only(
    model: &dyn WorkloadModel,
    opts: &CheckOptions,
    property: Check,
) -> Result<ConformanceReport, ConformanceFailure> {
    run(model, opts, Checker::new(model.name(), Some(property)))
}

entry_points! {
    WorkloadModel,
    /// Runs every workload-model property (see [`check_workload_model_with`])
    /// on a model built by `make`, under the plugin panic guard, and, once the
    /// model is dropped, [`Check::Destructor`]. What `hil plugins check` and
    /// [`crate::conformance_tests!`] run.
    check_workload_model_built_with,
    /// Runs one workload-model property alone on a model built by `make`
    /// (see [`check_workload_model_built_with`]).
    check_workload_model_built_only,
}

fn suite(
    started: super::Started<'_, dyn WorkloadModel>,
    opts: &CheckOptions,
) -> super::SuiteResult {
    run(started.first.as_ref(), opts, started.checker)
}

const WL0S: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

fn run(
    model: &dyn WorkloadModel,
    opts: &CheckOptions,
    mut c: Checker,
) -> Result<ConformanceReport, ConformanceFailure> {
    let caught = Caught(model);
    let model: &dyn WorkloadModel = &caught;
    let empty = QueryHistory::new();
    if c.wants(Check::EmptyHistory) {
        for wl0 in WL0S {
            let p = c.ok(
                Check::EmptyHistory,
                model.predict(&WorkloadInput::new(wl0, &empty, 0)),
            )?;
            c.check(Check::EmptyHistory, p.is_finite(), || {
                format!("WL_0 = {wl0}, empty history, t = 0: {p}")
            })?;
        }
    }
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &[9; 32]),
    );
    let strategy = query_history(40, 400);
    for _ in 0..200 {
        let history = strategy
            .new_tree(&mut runner)
            .map_err(|e| c.fail(Check::Predicts, format!("generating a history: {e}")))?
            .current();
        let t = history.last_time().unwrap_or(0) + 3;
        for wl0 in WL0S {
            let p = c.ok(
                Check::Predicts,
                model.predict(&WorkloadInput::new(wl0, &history, t)),
            )?;
            c.check(Check::FinitePrediction, p.is_finite(), || {
                format!("WL_0 = {wl0}, {} queries, t = {t}: {p}", history.len())
            })?;
            let q = c.ok(
                Check::Predicts,
                model.predict(&WorkloadInput::new(wl0, &history, t)),
            )?;
            c.check(
                Check::DeterministicPrediction,
                p.to_bits() == q.to_bits(),
                || {
                    format!(
                        "WL_0 = {wl0}, {} queries, t = {t}: {p} then {q}",
                        history.len()
                    )
                },
            )?;
            if !c.wants(Check::Counterfactual) {
                continue;
            }
            for kind in [
                QueryKind::default(),
                QueryKind {
                    response: hil_core::ResponseType::OpenEnded,
                    difficulty: hil_core::Difficulty::Hard,
                    distraction: hil_core::Distraction::Hard,
                },
            ] {
                let cf = c.ok(
                    Check::Counterfactual,
                    model.predict_if_queried(&WorkloadInput::new(wl0, &history, t), kind),
                )?;
                let mut h = history.clone();
                c.ok(Check::Counterfactual, h.push(t, kind))?;
                let direct = c.ok(
                    Check::Predicts,
                    model.predict(&WorkloadInput::new(wl0, &h, t)),
                )?;
                c.check(
                    Check::FinitePrediction,
                    cf.is_finite() && direct.is_finite(),
                    || {
                        format!(
                            "WL_0 = {wl0}, t = {t}, {} queries and one more: predict_if_queried = {cf}, predict = {direct}",
                            history.len()
                        )
                    },
                )?;
                c.check(
                    Check::Counterfactual,
                    (cf - direct).abs() <= 1e-12 * (1.0 + direct.abs()),
                    || {
                        format!(
                            "predict_if_queried = {cf}, predict with the query appended = {direct} (WL_0 = {wl0}, t = {t}, {kind:?})"
                        )
                    },
                )?;
            }
        }
    }
    long_history(&mut c, model, opts.steps())?;
    Ok(c.finish())
}

/// The long trajectory: one query per step, every kind in turn, for
/// `steps` steps, predicting after each.
fn long_history(
    c: &mut Checker,
    model: &dyn WorkloadModel,
    steps: usize,
) -> Result<(), ConformanceFailure> {
    let mut history = QueryHistory::new();
    for step in 1..=steps as u64 {
        c.ok(
            Check::Predicts,
            history.push(step, super::query_kind(step as usize)),
        )?;
        let p = c
            .ok(
                Check::Predicts,
                model.predict(&WorkloadInput::new(0.5, &history, step)),
            )
            .map_err(|mut f| {
                f.detail = format!("at query {step} of a growing history: {}", f.detail);
                f
            })?;
        c.check(Check::FinitePrediction, p.is_finite(), || {
            format!("WL_0 = 0.5, after {step} queries, one per step: {p}")
        })?;
    }
    Ok(())
}

/// A model whose panics become errors, as the plugin guard reports them, so
/// a panic fails the check that called it instead of unwinding through the
/// suite.
struct Caught<'a>(&'a dyn WorkloadModel);

impl Caught<'_> {
    fn run<T>(&self, method: &str, f: impl FnOnce() -> hil_core::Result<T>) -> hil_core::Result<T> {
        hil_plugin::call_guarded(&super::under_test(), self.0.name(), method, f)
    }
}

impl WorkloadModel for Caught<'_> {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> hil_core::Result<f64> {
        self.run("predict", || self.0.predict(input))
    }
    fn predict_if_queried(
        &self,
        input: &WorkloadInput<'_>,
        kind: QueryKind,
    ) -> hil_core::Result<f64> {
        self.run("predict_if_queried", || {
            self.0.predict_if_queried(input, kind)
        })
    }
}
