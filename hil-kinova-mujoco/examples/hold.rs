//! Diagnoses retention during the hold: runs attempts of every action on
//! every food (isolated) and prints, per (food, action), how many were on
//! the fork after the lift, how many after the hold, and the mean slip
//! along the tines during the hold.
//!
//! `cargo run --release -p hil-kinova-mujoco --example hold -- [trials] [hold_s] [free_step_s]`
use hil_kinova_mujoco::{FoodKind, FoodModel, Placement, Simulator, actions};
use rand::SeedableRng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let trials: usize = args.get(1).map_or(Ok(8), |s| s.parse())?;
    let hold: f64 = args.get(2).map_or(Ok(5.0), |s| s.parse())?;
    let mut sim = Simulator::new()?;
    if let Some(dt) = args.get(3) {
        sim.set_free_step(dt.parse()?)?;
    }
    let mut steps = 0u64;
    sim.set_hold(hold)?;
    for kind in FoodKind::SCENE {
        for a in actions() {
            let (mut lifted, mut held, mut slip, mut pierced) = (0, 0, 0.0, 0);
            for t in 0..trials {
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1000 + t as u64);
                let props = FoodModel::default_for(kind).sample(&mut rng);
                let items = vec![Placement {
                    props,
                    xy: [0.0, 0.0],
                    yaw: 0.3 * t as f64,
                }];
                let poses = sim.stage(&items, None, kind)?;
                let p = poses[0];
                let perceived = p.exact_target();
                let r = sim.execute(a, &perceived, None)?;
                steps += r.steps;
                if r.lifted_height > 0.03 {
                    lifted += 1;
                    slip += r.hold_slip;
                }
                if r.tines.max_pierced > 0 {
                    pierced += 1;
                }
                held += r.success as usize;
            }
            println!(
                "{:10} {:5} pierced {pierced}/{trials} lifted {lifted} held {held} mean hold slip {:.2} mm",
                kind.name(),
                a.name,
                1000.0 * slip / lifted.max(1) as f64
            );
        }
    }
    let t = sim.timing();
    println!(
        "attempts per CPU second {:.1}, in-step share {:.3}, execute steps/attempt {:.0}, {:.1} µs per mj_step (wall)",
        t.attempts as f64 / t.cpu.as_secs_f64(),
        t.in_step.as_secs_f64() / t.total.as_secs_f64(),
        steps as f64 / t.attempts as f64,
        1e6 * t.in_step.as_secs_f64() / t.steps as f64
    );
    Ok(())
}
