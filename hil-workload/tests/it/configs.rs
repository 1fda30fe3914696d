//! The `bundled` and `model_file` workload-model configs.

use hil_config::BuildContext;
use hil_config::WorkloadModelConfig;
use hil_core::QueryHistory;
use hil_core::WorkloadInput;

fn parse(json: &str) -> Result<Box<dyn WorkloadModelConfig>, serde_json::Error> {
    serde_json::from_str(json)
}

#[test]
fn bundled_config_builds_every_bundled_model() {
    let ctx = BuildContext::new(".", 0);
    for name in hil_workload::bundled::NAMES {
        let cfg = parse(&format!(r#"{{"type": "bundled", "name": "{name}"}}"#)).unwrap();
        let m = cfg.build(&ctx).unwrap();
        assert_eq!(m.name(), name);
        assert!(
            m.predict(&WorkloadInput::new(0.5, &QueryHistory::new(), 0))
                .unwrap()
                .is_finite()
        );
    }
    let e = parse(r#"{"type": "bundled", "name": "f9"}"#)
        .unwrap()
        .build(&ctx)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("f9") && e.contains("f1_sim"), "{e}");
    let e = parse(r#"{"type": "bundled", "name": "f1_sim", "nme": 1}"#)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("nme"), "{e}");
}

#[test]
fn model_file_config_resolves_against_the_config_dir() {
    let dir = std::env::temp_dir().join(format!("hil-workload-cfg-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("m")).unwrap();
    let model = hil_workload::bundled::load_fitted("f12_real").unwrap();
    model.save(dir.join("m/x.json")).unwrap();
    let cfg = parse(r#"{"type": "model_file", "path": "m/x.json"}"#).unwrap();
    let m = cfg.build(&BuildContext::new(&dir, 0)).unwrap();
    assert_eq!(m.name(), "f12_real");
    let e = cfg
        .build(&BuildContext::new("/nonexistent", 0))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("/nonexistent/m/x.json"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
