//! Runs one attempt of every action on every food and prints the reports.
//!
//! `cargo run -p hil-kinova-mujoco --example attempt`
use hil_kinova_mujoco::{FoodKind, FoodModel, Placement, Simulator, actions};
use rand::SeedableRng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut sim = Simulator::new()?;
    println!("home {:?}", sim.home());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    for kind in FoodKind::SCENE {
        for a in actions() {
            let props = FoodModel::default_for(kind).sample(&mut rng);
            let items = vec![Placement {
                props,
                xy: [0.0, 0.0],
                yaw: 0.3,
            }];
            let poses = sim.stage(&items, None, kind)?;
            let t = poses[0];
            let perceived = t.exact_target();
            let r = sim.execute(a, &perceived, None)?;
            println!(
                "{} {} success={} pitch={:.3} gamma={:.3} roll={:.3} handle={:.3} stop={:?} peak={:.1} tines={:?} h={:.3}",
                kind.name(),
                a.name,
                r.success,
                r.reached_pitch,
                r.reached_gamma,
                r.reached_roll,
                r.handle_roll,
                r.stop,
                r.peak_force,
                r.tines,
                r.final_height
            );
        }
    }
    let t = sim.timing();
    println!(
        "attempts/s {:.1}, in-step share {:.2}",
        t.attempts as f64 / t.total.as_secs_f64(),
        t.in_step.as_secs_f64() / t.total.as_secs_f64()
    );
    Ok(())
}
