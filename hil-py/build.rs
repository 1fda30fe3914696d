//! Embeds an rpath to the MuJoCo shared library that `scripts/setup-mujoco`
//! installs (via `MUJOCO_DYNAMIC_LINK_DIR` from `.cargo/config.toml`), so
//! the extension module imports without `LD_LIBRARY_PATH`: hil-experiments
//! links hil-kinova-mujoco, and so MuJoCo. Link arguments of a library's
//! build script do not reach other packages' artefacts, hence this copy
//! (as hil-cli's).

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
