use hil_kinova_mujoco::food::{FoodKind, FoodModel};
use hil_kinova_mujoco::sim::{Placement, Simulator};
use rand::SeedableRng;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut sim = Simulator::new()?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let props = FoodModel::default_for(FoodKind::Carrot).sample(&mut rng);
    println!("{props:?}");
    let items = vec![Placement { props, xy: [0.0, 0.0], yaw: 0.3 }];
    let poses = sim.stage(&items, FoodKind::Carrot)?;
    println!("{poses:?}");
    let b = sim.ids().food[1].body;
    let g = sim.ids().food[1].geom; println!("geom_quat {:?} body_quat {:?} xmat {:?}", sim.data().model().geom_quat()[g], sim.data().model().body_quat()[b], sim.data().geom_xmat()[g]);
    println!("mass {} inertia {:?}", sim.data().model().body_mass()[b], sim.data().model().body_inertia()[b]);
    Ok(())
}
