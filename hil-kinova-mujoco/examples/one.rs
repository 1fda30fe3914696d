//! temporary: one calibration trial.
use hil_core::{ArmId, Environment};
use hil_kinova_mujoco::calibrate::trial_seed;
use hil_kinova_mujoco::{FoodKind, KinovaFeedingConfig, KinovaFeedingEnv};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let food = FoodKind::parse(&a[1]).unwrap();
    let setting = a[2].clone();
    let action: usize = a[3].parse().unwrap();
    let trial: usize = a[4].parse().unwrap();
    let mut env = KinovaFeedingEnv::new(KinovaFeedingConfig {
        plate: vec![a[1].clone()],
        settings: vec![setting],
        ..Default::default()
    })
    .unwrap();
    env.reset(trial_seed(1, food, action, trial)).unwrap();
    env.next_item().unwrap();
    env.observe().unwrap();
    env.execute(ArmId(action)).unwrap();
    println!("{:?}", env.last_attempt());
}
