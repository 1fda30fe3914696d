//! Every model family: conformance suite, exact JSON round trips,
//! monotonicity of the constrained variants, consistency of the fast
//! cross-validation path with the models' own predictions.

use hil_conformance::check_workload_model;
use hil_conformance::strategies::{query_history, query_kind};
use hil_core::WorkloadInput;
use hil_core::{HilError, QueryHistory, WorkloadModel};
use hil_workload::datasets::{Dataset, DatasetId};
use hil_workload::features::SparseRow;
use hil_workload::models::{FittedModel, GrangerModel, GrangerVariant, ModelSpec, Provenance};
use hil_workload::select::{Candidate, SelectOptions, fit_on_all};
use hil_workload::synth::SynthConfig;
use proptest::prelude::*;
use std::path::Path;

fn small_d12() -> Dataset {
    let study = SynthConfig::small(10, 4).generate(3).unwrap();
    Dataset::build(&study, DatasetId::D12).unwrap()
}

fn all_candidates() -> Vec<Candidate> {
    let mut c = Candidate::table(&[1, 10]);
    c.push(Candidate::Granger {
        variant: GrangerVariant::Simulation,
        h: 10,
    });
    c
}

fn fitted(d: &Dataset) -> Vec<FittedModel> {
    let opts = SelectOptions::default();
    all_candidates()
        .into_iter()
        .map(|c| {
            let (spec, _) = fit_on_all(d, c, &opts).unwrap();
            FittedModel::new(
                format!("{}_{:?}", c.label(), c.history()),
                spec,
                Provenance::default(),
            )
        })
        .collect()
}

fn bundled() -> Vec<FittedModel> {
    hil_workload::bundled::NAMES
        .iter()
        .map(|n| hil_workload::bundled::load_fitted(n).unwrap())
        .collect()
}

#[test]
fn conformance_suite_passes_for_every_model() {
    let d = small_d12();
    for m in fitted(&d).iter().chain(&bundled()) {
        check_workload_model(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
        check_workload_model(m.spec.as_model()).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    }
}

#[test]
fn json_round_trip_gives_bit_identical_predictions() {
    let d = small_d12();
    for m in fitted(&d).iter().chain(&bundled()) {
        let back = FittedModel::from_json(&m.to_json(), "x.json".as_ref()).unwrap();
        assert_eq!(&back, m);
        for p in &d.pairs {
            let h = p.history.to_history();
            let a = m.predict(&WorkloadInput::new(p.wl0, &h, p.t)).unwrap();
            let b = back.predict(&WorkloadInput::new(p.wl0, &h, p.t)).unwrap();
            assert_eq!(a.to_bits(), b.to_bits(), "{}", m.name);
        }
    }
}

#[test]
fn model_files_from_other_versions_or_with_bad_fields_are_clear_errors() {
    let m = hil_workload::bundled::load_fitted("f1_sim").unwrap();
    let json = m.to_json();
    let v2 = json.replace("\"format_version\": 1", "\"format_version\": 2");
    // Each refusal names the file, and the record (line) and field where
    // the file says which.
    let at = |text: &str| match FittedModel::from_json(text, "m.json".as_ref()).unwrap_err() {
        HilError::Data {
            path,
            record,
            field,
            ..
        } => (path, record, field),
        other => panic!("not a data error: {other:?}"),
    };
    let (path, record, field) = at(&v2);
    assert_eq!(
        (path.as_path(), record, field.as_str()),
        (Path::new("m.json"), 3, "format_version")
    );
    let wrong = json.replace("\"history\": 10", "\"history\": 9");
    // A spec that disagrees with the weights, and an unknown key in the
    // spec: the `spec` field, saying which part.
    let extra = json.replace("\"gamma\"", "\"gama\": 1, \"gamma\"");
    for (text, part) in [(&wrong, "history"), (&extra, "gama")] {
        match FittedModel::from_json(text, "m.json".as_ref()).unwrap_err() {
            HilError::Data {
                path, field, why, ..
            } => {
                assert_eq!(
                    (path.as_path(), field.as_str()),
                    (Path::new("m.json"), "spec")
                );
                assert!(why.contains(part), "{why}");
            }
            other => panic!("not a data error: {other:?}"),
        }
    }
    assert_eq!(at("{}").2, "format");
    // bounds of the simulation variant are enforced on load
    let out = json.replacen("0.05,", "-0.5,", 1);
    assert!(FittedModel::from_json(&out, "m.json".as_ref()).is_err());
}

#[test]
fn sparse_design_path_matches_model_predictions() {
    let d = small_d12();
    for m in fitted(&d) {
        if let ModelSpec::Granger(g) = &m.spec {
            let w = g.coefficients();
            for p in &d.pairs {
                let fast = SparseRow::of_pair(p, g.history)
                    .dot_prefix(&w)
                    .clamp(0.0, 1.0);
                let slow = g
                    .predict(&WorkloadInput::new(p.wl0, &p.history.to_history(), p.t))
                    .unwrap();
                assert!((fast - slow).abs() < 1e-12, "{}: {fast} vs {slow}", m.name);
            }
        }
    }
}

#[test]
fn constrained_fits_respect_their_bounds() {
    let d = small_d12();
    for m in fitted(&d) {
        if let ModelSpec::Granger(g) = &m.spec {
            let (lo, hi) = g.variant.bounds(g.history);
            for (i, c) in g.coefficients().iter().enumerate() {
                assert!(
                    *c >= lo[i] && *c <= hi[i],
                    "{}: coefficient {i} = {c}",
                    m.name
                );
            }
        }
    }
}

fn monotone_models() -> Vec<FittedModel> {
    let d = small_d12();
    let mut v: Vec<FittedModel> = fitted(&d)
        .into_iter()
        .filter(|m| m.spec.is_monotone())
        .collect();
    v.extend(bundled().into_iter().filter(|m| m.spec.is_monotone()));
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Adding any query to any history never lowers the prediction.
    #[test]
    fn a_query_never_lowers_workload(
        history in query_history(12, 60),
        kind in query_kind(),
        extra_t in 0u64..5,
        wl0 in 0.0f64..=1.0,
    ) {
        let models = MONOTONE.with(|m| m.clone());
        let t = history.last_time().unwrap_or(0) + extra_t;
        for m in &models {
            let before = m.predict(&WorkloadInput::new(wl0, &history, t)).unwrap();
            let after = m.predict_if_queried(&WorkloadInput::new(wl0, &history, t), kind).unwrap();
            prop_assert!(before.is_finite() && after.is_finite());
            prop_assert!(after >= before, "{}: {} -> {}", m.name, before, after);
            // also a query inserted in the past (at the last query's time)
            let mut h = history.clone();
            if let Some(last) = history.last_time() {
                h.push(last, kind).unwrap();
                prop_assert!(m.predict(&WorkloadInput::new(wl0, &h, t)).unwrap() >= before);
            }
        }
    }

    /// Random Granger models of every variant round-trip exactly.
    #[test]
    fn random_granger_models_round_trip(
        coeffs in proptest::collection::vec(-3.0f64..3.0, 2 + 8 * 3),
        history in query_history(8, 30),
        wl0 in 0.0f64..=1.0,
    ) {
        let m = GrangerModel::from_coefficients(GrangerVariant::Plain, 3, &coeffs, None).unwrap();
        let f = FittedModel::new("r", ModelSpec::Granger(m), Provenance::default());
        let back = FittedModel::from_json(&f.to_json(), "r.json".as_ref()).unwrap();
        prop_assert_eq!(&back, &f);
        let t = history.last_time().unwrap_or(0);
        let a = f.predict(&WorkloadInput::new(wl0, &history, t)).unwrap();
        prop_assert!(a.is_finite() && (0.0..=1.0).contains(&a));
        prop_assert_eq!(a.to_bits(), back.predict(&WorkloadInput::new(wl0, &history, t)).unwrap().to_bits());
    }
}

thread_local! {
    static MONOTONE: Vec<FittedModel> = monotone_models();
}

#[test]
fn empty_history_of_the_constant_model_is_wl0() {
    let d = small_d12();
    let m = fitted(&d).remove(0);
    assert_eq!(
        m.predict(&WorkloadInput::new(0.3, &QueryHistory::new(), 0))
            .unwrap(),
        0.3
    );
    assert!(
        m.predict(&WorkloadInput::new(1.5, &QueryHistory::new(), 0))
            .is_err()
    );
}
