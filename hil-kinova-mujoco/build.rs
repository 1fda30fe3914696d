//! Embeds an rpath to the MuJoCo shared library installed by
//! `scripts/setup-mujoco`, so `cargo build`, `run` and `test` work without
//! `LD_LIBRARY_PATH`. The directory comes from `MUJOCO_DYNAMIC_LINK_DIR`
//! (set in `.cargo/config.toml`), the same variable mujoco-rs links with.

use std::path::Path;

fn main() {
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

    // Link args reach only this package's own artefacts (tests, examples);
    // binaries in other packages (hil-cli) add the same rpath in their build.rs.
    println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
}
