//! Helpers the Kinova integration tests share.

use hil_kinova_mujoco::{Action, AttemptReport, FoodKind, FoodModel, Placement, Simulator};
use rand::SeedableRng;

/// Stages one item of `kind`, sampled from its model with `seed`, at `xy`
/// with major-axis `yaw`, and executes `action` on its exact pose.
pub fn attempt_at(
    sim: &mut Simulator,
    kind: FoodKind,
    action: &Action,
    seed: u64,
    xy: [f64; 2],
    yaw: f64,
) -> AttemptReport {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let props = FoodModel::default_for(kind).sample(&mut rng);
    let items = vec![Placement { props, xy, yaw }];
    let pose = sim.stage(&items, None, kind).unwrap()[0];
    sim.execute(action, &pose.exact_target(), None).unwrap()
}

/// Asserts that `reached` is within `tol` of `commanded`, naming the
/// action and the quantity.
pub fn assert_reached(action: &Action, what: &str, reached: f64, commanded: f64, tol: f64) {
    assert!(
        (reached - commanded).abs() < tol,
        "{}: {what} {reached} (commanded {commanded})",
        action.name
    );
}
