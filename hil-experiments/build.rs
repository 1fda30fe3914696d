//! Embeds the MuJoCo rpath in this package's artefacts (see `hil-build`).

fn main() {
    hil_build::mujoco_rpath();
}
