//! # hil-build
//!
//! Build-script helpers shared by hil's crates, so each rule is written
//! once. Used as a `[build-dependencies]` entry.
//!
//! [`mujoco_rpath`] embeds an rpath to the MuJoCo shared library that
//! `scripts/setup-mujoco` installs, so binaries, tests and doctests that
//! link hil-kinova-mujoco start without `LD_LIBRARY_PATH`. Link arguments
//! of one package's build script reach only that package's own artefacts,
//! so every package whose artefacts link MuJoCo calls it from its own
//! `build.rs`.

use std::path::Path;

/// Prints the cargo instructions that add an rpath to
/// `MUJOCO_DYNAMIC_LINK_DIR` (set by `.cargo/config.toml`, the variable
/// mujoco-rs links with) when the calling package builds with its
/// `physics` feature; warns when the directory has no `libmujoco.so`.
pub fn mujoco_rpath() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    // Without the `physics` feature nothing links MuJoCo.
    if std::env::var_os("CARGO_FEATURE_PHYSICS").is_none() {
        return;
    }
    let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") else {
        println!(
            "cargo::warning=MUJOCO_DYNAMIC_LINK_DIR is not set; run scripts/setup-mujoco and build from the repository"
        );
        return;
    };
    if !Path::new(&dir).join("libmujoco.so").exists() {
        println!("cargo::warning=no libmujoco.so in {dir}; run scripts/setup-mujoco first");
    }
    println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
}

/// The same rpath for a package that has no `physics` feature of its own
/// but may link MuJoCo through another package's (the workspace's
/// integration tests, which link hil-experiments): added whenever
/// `MUJOCO_DYNAMIC_LINK_DIR` is set, silently, since an rpath to a
/// directory nothing is loaded from is harmless.
pub fn mujoco_rpath_unconditional() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
