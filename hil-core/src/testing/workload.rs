use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use super::strategies::query_history;
use super::{Checker, ConformanceFailure, ConformanceReport};
use crate::{QueryKind, WorkloadInput, WorkloadModel};

/// Runs the workload-model conformance suite.
///
/// Checks, over WL_0 in {0, 0.25, 0.5, 0.75, 1} and 200 random histories:
/// predictions are finite; repeated calls agree; `predict_if_queried` equals
/// `predict` on the history with the query appended; an empty history at
/// t = 0 is accepted.
pub fn check_workload_model(
    model: &dyn WorkloadModel,
) -> Result<ConformanceReport, ConformanceFailure> {
    let mut c = Checker::new(model.name());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &[9; 32]),
    );
    let strategy = query_history(40, 400);
    let empty = crate::QueryHistory::new();
    for wl0 in [0.0, 0.25, 0.5, 0.75, 1.0] {
        let p = c.ok(
            "empty history",
            model.predict(&WorkloadInput::new(wl0, &empty, 0)),
        )?;
        c.check("finite", p.is_finite(), || {
            format!("WL_0 = {wl0}, empty history: {p}")
        })?;
    }
    for _ in 0..200 {
        let history = strategy
            .new_tree(&mut runner)
            .map_err(|e| c.fail("generate", e.to_string()))?
            .current();
        let t = history.last_time().unwrap_or(0) + 3;
        for wl0 in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let p = c.ok(
                "predict",
                model.predict(&WorkloadInput::new(wl0, &history, t)),
            )?;
            c.check("finite", p.is_finite(), || {
                format!("WL_0 = {wl0}, {} queries, t = {t}: {p}", history.len())
            })?;
            let q = c.ok(
                "predict",
                model.predict(&WorkloadInput::new(wl0, &history, t)),
            )?;
            c.check("deterministic", p.to_bits() == q.to_bits(), || {
                format!("{p} then {q}")
            })?;
            for kind in [
                QueryKind::default(),
                QueryKind {
                    response: crate::ResponseType::OpenEnded,
                    difficulty: crate::Difficulty::Hard,
                    distraction: crate::Distraction::Hard,
                },
            ] {
                let cf = c.ok(
                    "counterfactual",
                    model.predict_if_queried(&WorkloadInput::new(wl0, &history, t), kind),
                )?;
                let mut h = history.clone();
                c.ok("counterfactual", h.push(t, kind))?;
                let direct = c.ok(
                    "counterfactual",
                    model.predict(&WorkloadInput::new(wl0, &h, t)),
                )?;
                c.check(
                    "counterfactual",
                    (cf - direct).abs() <= 1e-12 * (1.0 + direct.abs()),
                    || {
                        format!(
                            "predict_if_queried = {cf}, predict with the query appended = {direct}"
                        )
                    },
                )?;
            }
        }
    }
    Ok(c.finish())
}
