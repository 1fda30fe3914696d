//! `hil data` and `hil reproduce` end to end on a small generated dataset
//! (d = 224, 2 images per setting) so that the debug build stays fast.

mod common;

use std::path::Path;

use common::hil;

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn data_generate_check_then_reproduce_quick() {
    let root = std::env::temp_dir().join(format!("hil-cli-reproduce-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let ds = root.join("ds");
    let ds_s = ds.to_str().unwrap();
    let out = hil(&[
        "data",
        "generate",
        "--out",
        ds_s,
        "--dim",
        "224",
        "--images-per-setting",
        "2",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(ds.join("dataset.toml").exists() && ds.join("readout.npy").exists());
    // Refuses to overwrite without --force.
    let again = hil(&["data", "generate", "--out", ds_s, "--dim", "224"]);
    assert!(!again.status.success() && text(&again).contains("--force"));
    let check = hil(&["data", "check", ds_s]);
    assert!(check.status.success(), "{}", text(&check));
    assert!(text(&check).contains("banana") && text(&check).contains("synthetic"));

    let res = root.join("out");
    let out = hil(&[
        "reproduce",
        "--quick",
        "--quiet",
        "--dataset",
        ds_s,
        "--out",
        res.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(res.join("results.json")).unwrap()).unwrap();
    // 3 models × 8 w_task × 4 policies, and the two cross-data rows.
    assert_eq!(json["rows"].as_array().unwrap().len(), 96);
    assert_eq!(json["cross"].as_array().unwrap().len(), 2);
    assert!(json["provenance"].as_str().unwrap().contains("synthetic"));
    let tables = std::fs::read_to_string(res.join("tables.md")).unwrap();
    assert!(tables.contains("Table I") && tables.contains("0.292 ± 0.113"));
    for f in ["qg_rollout.svg", "workload_5_items.svg"] {
        assert!(Path::new(&res.join(f)).exists(), "{f}");
    }
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn reproduce_rejects_a_bad_split() {
    let root = std::env::temp_dir().join(format!("hil-cli-badsplit-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let settings = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/configs/paper-protocol.toml"),
    )
    .unwrap()
    .replace(
        "test = [\"banana\", \"carrot\"]",
        "test = [\"banana\", \"grape\"]",
    );
    let p = root.join("s.toml");
    std::fs::write(&p, settings).unwrap();
    let out = hil(&["reproduce", "--quiet", "--settings", p.to_str().unwrap()]);
    assert!(!out.status.success());
    let t = text(&out);
    assert!(t.contains("grape") && t.contains("split.test"), "{t}");
    std::fs::remove_dir_all(&root).unwrap();
}
