//! Embeds an rpath to the MuJoCo shared library that `scripts/setup-mujoco`
//! installs (via `MUJOCO_DYNAMIC_LINK_DIR` from `.cargo/config.toml`), so
//! the extension module built with the `kinova` feature imports without
//! `LD_LIBRARY_PATH`. Link arguments of a library's
//! build script do not reach other packages' artefacts, hence this copy
//! (as hil-cli's).

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    // Without the `kinova` feature nothing links MuJoCo.
    if std::env::var_os("CARGO_FEATURE_KINOVA").is_none() {
        return;
    }
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
