//! Building the plugin crates the tests load.
//!
//! Tests build the cdylibs themselves with the cargo that runs them, into
//! the same target directory and profile, so a fresh clone needs nothing
//! but `cargo test`. Cargo's own lock serialises concurrent builds.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// Every plugin crate the integration tests load.
pub const PLUGIN_CRATES: [&str; 8] = [
    "hil-example-policy-thompson",
    "hil-example-workload-fatigue",
    "hil-example-channel-noisy-expert",
    "hil-example-env-grasp",
    "hil-test-plugin-panicky",
    "hil-test-plugin-mismatched-abi",
    "hil-test-plugin-mismatched-version",
    "hil-test-plugin-not-a-plugin",
];

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace root")
        .to_path_buf()
}

/// `(target dir, profile dir)` of this test executable
/// (`<target>/<profile>/deps/<test>`).
fn layout() -> (PathBuf, String) {
    let exe = std::env::current_exe().expect("current exe");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("test executables live in <target>/<profile>/deps");
    let target = profile_dir.parent().expect("<target>").to_path_buf();
    let profile = profile_dir
        .file_name()
        .expect("profile dir")
        .to_string_lossy()
        .into_owned();
    (target, profile)
}

/// Builds every plugin crate once per test process and returns the
/// directory holding the libraries.
pub fn plugin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let (target, profile) = layout();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| env!("CARGO").to_string());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(workspace_root())
            .env("CARGO_TARGET_DIR", &target)
            .args(["build", "--quiet"]);
        match profile.as_str() {
            "debug" => {}
            "release" => {
                cmd.arg("--release");
            }
            other => {
                cmd.args(["--profile", other]);
            }
        }
        for c in PLUGIN_CRATES {
            cmd.args(["-p", c]);
        }
        let out = cmd
            .output()
            .expect("running cargo build for the plugin crates");
        assert!(
            out.status.success(),
            "building the plugin crates failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        target.join(profile)
    })
}

/// The path of the library built from crate `krate` (e.g. `hil-example-env-grasp`).
pub fn lib(krate: &str) -> PathBuf {
    plugin_dir().join(format!(
        "{}{}{}",
        std::env::consts::DLL_PREFIX,
        krate.replace('-', "_"),
        std::env::consts::DLL_SUFFIX
    ))
}

/// A fresh scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hil-plugin-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}
