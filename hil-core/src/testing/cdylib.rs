//! Building plugin libraries from tests.
//!
//! A test that loads a plugin should build it itself, with the cargo that
//! runs the test and in the same profile, so a fresh clone needs nothing but
//! `cargo test` and the plugin matches the host's build facts. Cargo's own
//! lock serialises concurrent builds.
//!
//! The plugins go to their own target directory, `<target>/plugin-build`:
//! built alone, a crate's dependencies get other features than in the
//! `cargo test` that runs us, and cargo may give both builds the same file
//! names. Sharing one directory would let the nested build overwrite
//! libraries the outer `cargo test` links later (its doctests), so the first
//! run pays for one extra build of hil-core and its dependencies instead.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{HilError, Result};

/// `(target dir, profile dir name)` of the running test executable, which
/// lives in `<target>/<profile>/deps/`.
pub fn target_layout() -> Result<(PathBuf, String)> {
    let exe = std::env::current_exe().map_err(|e| HilError::io("locating", "current exe", e))?;
    let profile_dir = exe.parent().and_then(Path::parent).ok_or_else(|| {
        HilError::state(
            "build_cdylibs",
            "the test executable is not in <target>/<profile>/deps",
        )
    })?;
    let target = profile_dir.parent().ok_or_else(|| {
        HilError::state(
            "build_cdylibs",
            "no target directory above the profile directory",
        )
    })?;
    let profile = profile_dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok((target.to_path_buf(), profile))
}

/// Runs `cargo build -p <crate>...` in `workspace` with the running test's
/// profile, into `<target>/plugin-build`; returns the directory holding the
/// built libraries (use [`cdylib_path`] for a crate's file).
pub fn build_cdylibs(workspace: &Path, crates: &[&str]) -> Result<PathBuf> {
    let (target, profile) = target_layout()?;
    let target = target.join("plugin-build");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace)
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
    for c in crates {
        cmd.args(["-p", c]);
    }
    let out = cmd
        .output()
        .map_err(|e| HilError::io("running", "cargo build", e))?;
    if !out.status.success() {
        return Err(HilError::backend(
            "cargo build",
            String::from_utf8_lossy(&out.stderr).into_owned(),
        ));
    }
    Ok(target.join(profile))
}

/// The file cargo builds for cdylib crate `krate` in `dir`
/// (`libmy_plugin.so`, `libmy_plugin.dylib`, `my_plugin.dll`).
pub fn cdylib_path(dir: &Path, krate: &str) -> PathBuf {
    dir.join(format!(
        "{}{}{}",
        std::env::consts::DLL_PREFIX,
        krate.replace('-', "_"),
        std::env::consts::DLL_SUFFIX
    ))
}
