//! Example plugin: **grasp choice for assistive pick-and-place**.
//!
//! A robot fetches household objects for a person (a mug, a pill box, a
//! phone...). For each object it chooses one of five grasps; it may ask the
//! person which one to use. The context is the object's descriptor (width,
//! height, mass, rigidity, handle) observed with noise, plus two pose
//! features. Each object has a success probability per grasp; the numbers
//! are synthetic, chosen to be plausible (handles favour a hook grasp, thin
//! flat objects a pinch), not measured.
//!
//! ```
//! use hil_plugin::Params;
//! use hil_core::Environment;
//! use hil_config::BuildContext;
//! let mut env = hil_example_env_grasp::build(&Params::toml("n_objects = 3"), &BuildContext::new(".", 0)).unwrap();
//! env.reset(1).unwrap();
//! let item = env.next_item().unwrap().unwrap();
//! assert_eq!(env.observe().unwrap().dim(), env.context_dim());
//! assert_eq!(env.action_space().len(), 5);
//! # let _ = item;
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use hil_config::BuildContext;
use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Environment, HilError, Item, Outcome, Result,
};
use hil_plugin::{Params, Registrar};

/// The name the plugin registers.
pub const NAME: &str = "grasp_choice";

/// The grasps, in arm order.
pub const GRASPS: [&str; 5] = [
    "top_pinch",
    "side_pinch",
    "top_power",
    "side_power",
    "handle_hook",
];

/// (name, [width m, height m, mass kg, rigidity 0..1, handle 0/1], success per grasp).
type ObjectRow = (&'static str, [f64; 5], [f64; 5]);

/// The objects (synthetic success probabilities).
#[rustfmt::skip]
pub const OBJECTS: [ObjectRow; 8] = [
    ("mug",          [0.09, 0.10, 0.35, 1.0, 1.0], [0.30, 0.45, 0.60, 0.70, 0.92]),
    ("water_bottle", [0.07, 0.22, 0.55, 0.6, 0.0], [0.20, 0.40, 0.35, 0.90, 0.05]),
    ("pill_box",     [0.06, 0.03, 0.05, 1.0, 0.0], [0.88, 0.60, 0.40, 0.25, 0.02]),
    ("phone",        [0.07, 0.01, 0.18, 1.0, 0.0], [0.55, 0.80, 0.20, 0.15, 0.02]),
    ("apple",        [0.08, 0.08, 0.20, 0.9, 0.0], [0.35, 0.40, 0.85, 0.75, 0.02]),
    ("towel",        [0.25, 0.05, 0.30, 0.1, 0.0], [0.80, 0.30, 0.60, 0.20, 0.10]),
    ("spoon",        [0.03, 0.01, 0.04, 1.0, 0.0], [0.90, 0.35, 0.10, 0.05, 0.02]),
    ("basket",       [0.30, 0.20, 0.60, 0.7, 1.0], [0.10, 0.25, 0.40, 0.45, 0.95]),
];

/// Parameters (all optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GraspParams {
    /// Objects per episode (≥ 1).
    pub n_objects: usize,
    /// Standard deviation scale of the observation noise (≥ 0).
    pub noise: f64,
    /// Restrict episodes to these objects (default: all).
    pub objects: Option<Vec<String>>,
}

impl Default for GraspParams {
    fn default() -> Self {
        Self {
            n_objects: 8,
            noise: 0.05,
            objects: None,
        }
    }
}

/// The grasp-choice environment.
#[derive(Clone, Debug)]
pub struct GraspEnv {
    p: GraspParams,
    pool: Vec<usize>,
    actions: ActionSpace,
    rng: ChaCha8Rng,
    next: usize,
    current: Option<(Item, usize)>,
    calls: CallOrder,
}

impl GraspEnv {
    /// Validates the parameters.
    pub fn new(p: GraspParams) -> Result<Self> {
        if p.n_objects == 0 {
            return Err(HilError::invalid_parameter(
                "n_objects",
                0,
                "must be at least 1",
            ));
        }
        if !(p.noise.is_finite() && p.noise >= 0.0) {
            return Err(HilError::invalid_parameter(
                "noise",
                p.noise,
                "must be finite and ≥ 0",
            ));
        }
        let pool = match &p.objects {
            None => (0..OBJECTS.len()).collect(),
            Some(names) if names.is_empty() => {
                return Err(HilError::invalid_parameter(
                    "objects",
                    "[]",
                    "must name at least one object",
                ));
            }
            Some(names) => names
                .iter()
                .map(|n| {
                    OBJECTS.iter().position(|o| o.0 == n).ok_or_else(|| {
                        HilError::invalid_parameter(
                            "objects",
                            n,
                            format!(
                                "unknown object; known: {}",
                                OBJECTS.iter().map(|o| o.0).collect::<Vec<_>>().join(", ")
                            ),
                        )
                    })
                })
                .collect::<Result<_>>()?,
        };
        Ok(Self {
            p,
            pool,
            actions: ActionSpace::new(GRASPS)?,
            rng: ChaCha8Rng::seed_from_u64(0),
            next: 0,
            current: None,
            calls: CallOrder::new(NAME),
        })
    }

    fn object(&self) -> Result<usize> {
        self.current
            .as_ref()
            .map(|c| c.1)
            .ok_or_else(|| HilError::state(NAME, "no current object: call next_item first"))
    }
}

impl Environment for GraspEnv {
    fn name(&self) -> &str {
        NAME
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        7
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.current = None;
        self.calls.on_reset();
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        if self.next >= self.p.n_objects {
            self.current = None;
            self.calls.on_next_item(false);
            return Ok(None);
        }
        let obj = self.pool[self.rng.random_range(0..self.pool.len())];
        let item = Item::new(self.next, OBJECTS[obj].0.to_string()).with_description(format!(
            "a {} on the table",
            OBJECTS[obj].0.replace('_', " ")
        ));
        self.next += 1;
        self.current = Some((item.clone(), obj));
        self.calls.on_next_item(true);
        Ok(Some(item))
    }
    fn observe(&mut self) -> Result<Context> {
        self.calls.on_observe()?;
        let obj = self.object()?;
        let s = self.p.noise;
        let mut x: Vec<f64> = OBJECTS[obj]
            .1
            .iter()
            .map(|v| v + s * (self.rng.random::<f64>() - 0.5))
            .collect();
        // Pose: yaw and distance offsets the grasp planner would see.
        x.push(self.rng.random_range(-1.0..1.0));
        x.push(self.rng.random_range(-1.0..1.0));
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.actions.check(arm)?;
        self.calls.on_execute()?;
        let obj = self.object()?;
        let p = OBJECTS[obj].2[arm.0];
        Ok(Outcome::new(self.rng.random_bool(p)).with_success_probability(p))
    }
    fn best_action(&self) -> Option<ArmId> {
        let obj = self.object().ok()?;
        let probs = OBJECTS[obj].2;
        (0..probs.len())
            .max_by(|a, b| probs[*a].total_cmp(&probs[*b]))
            .map(ArmId)
    }
    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref().map(|c| &c.0)
    }
}

/// The factory.
pub fn build(params: &Params, _ctx: &BuildContext) -> Result<Box<dyn Environment>> {
    Ok(Box::new(GraspEnv::new(params.parse(NAME)?)?))
}

/// Registers the environment.
pub fn register(r: &mut Registrar<'_>) {
    r.environment(
        NAME,
        "choose a grasp for assistive pick-and-place of household objects (synthetic success rates)",
        build,
    );
}

hil_plugin::declare_plugin!(register);

#[cfg(test)]
mod tests {
    use super::*;

    // One test per property.
    hil_conformance::conformance_tests! {
        environment grasp_choice {
            options: hil_conformance::CheckOptions::default().with_attempts(3),
            make: |opts| build(&Params::empty(), &opts.build_context()),
        }
    }

    #[test]
    fn rejects_unknown_objects() {
        let e = build(
            &Params::toml("objects = [\"mugg\"]"),
            &BuildContext::new(".", 0),
        )
        .err()
        .unwrap();
        assert!(e.to_string().contains("mugg"), "{e}");
    }
}
