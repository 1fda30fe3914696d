//! A `hil` built without the `physics` feature keeps `hil kinova` and
//! `hil demo kinova`, and they fail saying how to enable MuJoCo.

use crate::common::hil;

#[test]
fn kinova_commands_say_how_to_enable_physics() {
    for args in [
        &["kinova", "calibrate", "--trials", "3"][..],
        &["demo", "kinova", "--seeds", "2"][..],
    ] {
        let out = hil(args);
        assert!(!out.status.success(), "{args:?} succeeded without physics");
        let stderr = String::from_utf8_lossy(&out.stderr);
        // The message is the remedy itself: the setup script and the feature.
        assert!(
            stderr.contains(hil_kinova_mujoco::ENABLE_PHYSICS),
            "{args:?}: {stderr}"
        );
    }
}
