//! Property tests of the workload-model JSON reader: mutated model files
//! (truncations, bit flips, junk, deep nesting, huge and non-finite
//! numbers) are either read or refused with an error that names the file,
//! never a panic; a model that is read predicts without panicking.

use std::path::Path;

use hil_conformance::mutate::mutated;
use hil_core::WorkloadInput;
use hil_core::{HilError, QueryHistory, QueryKind, WorkloadModel};
use hil_workload::models::{
    AverageModel, ConstantModel, ExpImpulseModel, FittedModel, ModelSpec, Provenance,
};
use proptest::prelude::*;

const FILE: &str = "fuzz/model.json";

/// Valid model files of every family: the bundled ones (Granger) and one
/// each of the others.
fn bases() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut out: Vec<String> = ["f1_sim", "f1_real", "f12_real"]
        .iter()
        .map(|n| std::fs::read_to_string(dir.join(format!("{n}.json"))).unwrap())
        .collect();
    for spec in [
        ModelSpec::Constant(ConstantModel {}),
        ModelSpec::Average(AverageModel { value: 0.4 }),
        ModelSpec::ExpImpulse(ExpImpulseModel {
            decay: 0.05,
            impulse: [0.1, 0.2, 0.0, 0.05, 0.1, 0.0, 0.02, 0.04],
        }),
    ] {
        out.push(FittedModel::new("m", spec, Provenance::default()).to_json());
    }
    out
}

fn histories() -> Vec<QueryHistory> {
    let mut long = QueryHistory::new();
    for t in [0, 1, 1, 7, 30, 1000] {
        long.push(t, QueryKind::default()).unwrap();
    }
    vec![QueryHistory::new(), long]
}

fn check(bytes: &[u8]) -> Result<(), TestCaseError> {
    let text = String::from_utf8_lossy(bytes);
    match FittedModel::from_json(&text, Path::new(FILE)) {
        Ok(m) => {
            for h in histories() {
                for t in [0, 5, 2000] {
                    // Any result, but no panic.
                    let _ = m.predict(&WorkloadInput::new(0.5, &h, t));
                }
            }
            Ok(())
        }
        Err(HilError::Data { path, record, .. }) => {
            prop_assert_eq!(path.as_path(), Path::new(FILE));
            prop_assert!(record >= 1);
            Ok(())
        }
        Err(other) => Err(TestCaseError::fail(format!(
            "not a located data error: {other:?}"
        ))),
    }
}

#[test]
fn the_unmutated_models_are_valid() {
    for b in bases() {
        FittedModel::from_json(&b, Path::new(FILE)).unwrap();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn mutated_model_files_are_read_or_refused_naming_the_file(
        bytes in proptest::sample::select(bases())
            .prop_flat_map(|b| mutated(b.into_bytes(), 4))
    ) {
        check(&bytes)?;
    }
}
