//! Embeds the MuJoCo rpath: these suites link hil-experiments, which links
//! MuJoCo when a test run enables its `physics` feature (see `hil-build`).

fn main() {
    hil_build::mujoco_rpath_unconditional();
}
