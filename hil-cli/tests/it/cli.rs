//! The `hil` binary as a user meets it.

use crate::common;
use common::hil;

#[test]
fn version_and_help() {
    let out = hil(&["--version"]);
    assert!(out.status.success());
    let v = String::from_utf8_lossy(&out.stdout);
    assert!(
        v.starts_with("hil ") && v.contains(env!("CARGO_PKG_VERSION")),
        "{v}"
    );

    let out = hil(&["--help"]);
    assert!(out.status.success());
    let h = String::from_utf8_lossy(&out.stdout);
    assert!(h.contains("run") && h.contains("synthetic"), "{h}");

    let out = hil(&["run", "--help"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("--config"));
}

#[test]
fn run_reports_a_missing_config_file() {
    let out = hil(&["run", "--config", "/nonexistent/experiment.toml"]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("/nonexistent/experiment.toml"), "{e}");
}

#[test]
fn run_locates_config_errors() {
    let dir = std::env::temp_dir().join(format!("hil-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        "seed = 1\n\n[session]\nn_att = 3\nwl_0 = 0.5\n\n[environment]\ntype = \"x\"\n",
    )
    .unwrap();
    let out = hil(&["run", "--config", path.to_str().unwrap()]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    // Either fault may be reported first; each is located.
    assert!(
        (e.contains("bad.toml:5:") && e.contains("session.wl_0"))
            || (e.contains("bad.toml:8:") && e.contains("environment.type")),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
