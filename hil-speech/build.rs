//! Links Debian's pocketsphinx (5prealpha) and sphinxbase when the
//! `engines` feature is on; without it the crate links nothing extra.
//! Embeds the MuJoCo rpath too (see `hil-build`): the end-to-end test links
//! hil-experiments, which a workspace build with `physics` links to MuJoCo.
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_ENGINES").is_some() {
        println!("cargo:rustc-link-lib=pocketsphinx");
        println!("cargo:rustc-link-lib=sphinxbase");
    }
    hil_build::mujoco_rpath_unconditional();
}
