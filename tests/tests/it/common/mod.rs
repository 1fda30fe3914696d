//! The plugin crates the tests load, built once per test process.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use hil_conformance::cdylib::{build_cdylibs, cdylib_path};

/// Every plugin crate the integration tests load.
pub const PLUGIN_CRATES: [&str; 9] = [
    "hil-example-policy-thompson",
    "hil-example-workload-fatigue",
    "hil-example-channel-noisy-expert",
    "hil-example-env-grasp",
    "hil-example-plugin-guide",
    "hil-test-plugin-panicky",
    "hil-test-plugin-mismatched-abi",
    "hil-test-plugin-mismatched-version",
    "hil-test-plugin-not-a-plugin",
];

/// The workspace root.
pub fn workspace_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace root")
}

/// The directory of the built libraries (built on first use).
pub fn plugin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| build_cdylibs(workspace_root(), &PLUGIN_CRATES).unwrap())
}

/// The library built from crate `krate` (e.g. `hil-example-env-grasp`).
pub fn lib(krate: &str) -> PathBuf {
    cdylib_path(plugin_dir(), krate)
}

/// Set (to anything) to keep the scratch directories of failed tests for
/// a look afterwards; they are removed otherwise, passed or failed (the
/// blank-folder guide test leaves a plugin build of several hundred MB).
pub const KEEP_SCRATCH_ENV: &str = "HIL_KEEP_TEST_DIRS";

/// A test's scratch directory, removed when dropped: at the end of the
/// test, and while unwinding from its failure (then kept, and its path
/// printed, if [`KEEP_SCRATCH_ENV`] is set).
#[derive(Debug)]
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() && std::env::var_os(KEEP_SCRATCH_ENV).is_some() {
            eprintln!("kept {} ({KEEP_SCRATCH_ENV} is set)", self.0.display());
            return;
        }
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh scratch directory for one test (see [`Scratch`]).
pub fn scratch(name: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!("hil-plugin-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    Scratch(dir)
}

/// Held by every test that drops a plugin object whose destructor panics:
/// those panics land in one process-wide list
/// (`plugin::take_destructor_panics`), and the tests share a process.
pub fn destructor_panics_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}
