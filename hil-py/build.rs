//! Embeds an rpath to the MuJoCo shared library that `scripts/setup-mujoco`
//! installs (via `MUJOCO_DYNAMIC_LINK_DIR` from `.cargo/config.toml`), so
//! the extension module built with the `kinova` feature imports without
//! `LD_LIBRARY_PATH`. Link arguments of a library's
//! build script do not reach other packages' artefacts, hence this copy
//! (as hil-cli's).

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    // Set even without the `kinova` feature: a workspace build that turns
    // on hil-kinova-mujoco's `physics` for another crate links MuJoCo here
    // too (feature unification), and an unused rpath costs nothing.
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
