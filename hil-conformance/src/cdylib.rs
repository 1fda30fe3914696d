//! Building plugin libraries from tests.
//!
//! A test that loads a plugin should build it itself, with the cargo that
//! runs the test and in the same profile, so a fresh clone needs nothing but
//! `cargo test` and the plugin matches the host's build facts. Cargo's own
//! lock serialises concurrent builds.
//!
//! A test run builds them once: after a build, a stamp next to the
//! libraries records a fingerprint of what went into it (the crates asked
//! for, the profile, the toolchain, `RUSTFLAGS`, and the size and
//! modification time of every file of the workspace outside `target/`,
//! `.git/` and `third_party/`); later calls, from any test process, whose
//! fingerprint matches and whose libraries exist return at once instead of
//! running a nested cargo. Cargo's own lock serialises concurrent builds.
//!
//! The plugins go to their own target directory, `<target>/plugin-build`:
//! built alone, a crate's dependencies get other features than in the
//! `cargo test` that runs us, and cargo may give both builds the same file
//! names. Sharing one directory would let the nested build overwrite
//! libraries the outer `cargo test` links later (its doctests), so the first
//! run pays for one extra build of hil-core and its dependencies instead.

use std::path::{Path, PathBuf};
use std::process::Command;

use hil_core::{HilError, Result};

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
    let libs = target.join(&profile);
    let fingerprint = fingerprint(workspace, crates, &profile);
    let stamp = libs.join(format!(
        ".hil-plugins-{:016x}",
        hash(crates.join(" ").as_bytes())
    ));
    let built = |c: &&str| cdylib_path(&libs, c).exists();
    if std::fs::read_to_string(&stamp).is_ok_and(|s| s == fingerprint) && crates.iter().all(built) {
        return Ok(libs);
    }
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
    // A failed write only costs the next caller a no-op cargo run.
    let _ = std::fs::write(&stamp, &fingerprint);
    Ok(libs)
}

/// FNV-1a, enough to name a stamp file.
fn hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// What a build of `crates` depends on, as text (see the module docs).
fn fingerprint(workspace: &Path, crates: &[&str], profile: &str) -> String {
    let mut files = Vec::new();
    walk(workspace, workspace, &mut files);
    files.sort();
    let mut text = format!(
        "crates {crates:?}\nprofile {profile}\nrustc {}\nrustflags {:?} {:?}\n",
        hil_plugin::BuildFacts::current()
            .rustc_version
            .to_string_lossy(),
        std::env::var("RUSTFLAGS").ok(),
        std::env::var("CARGO_ENCODED_RUSTFLAGS").ok(),
    );
    for f in files {
        text.push_str(&f);
        text.push('\n');
    }
    format!("{:016x} over {} bytes", hash(text.as_bytes()), text.len())
}

/// `path size mtime` of every file under `dir`, skipping build output,
/// version control and vendored libraries.
fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name();
        if matches!(name.to_str(), Some("target" | ".git" | "third_party")) {
            continue;
        }
        let Ok(meta) = e.metadata() else { continue };
        if meta.is_dir() {
            walk(root, &path, out);
        } else {
            let mtime = meta
                .modified()
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos());
            let rel = path.strip_prefix(root).unwrap_or(&path);
            out.push(format!("{} {} {mtime}", rel.display(), meta.len()));
        }
    }
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
