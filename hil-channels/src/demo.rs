//! Small built-in components for trying the channels and the interaction
//! record without a robot: a plate of foods (`demo_plate`) and a simple
//! learning policy that sometimes asks (`demo_learner`).
//!
//! They are deliberately simple and are not the paper's testbed or its
//! policies (those live in `hil-envs` and `hil-policies`). The success rates
//! are the published per-food rates of Feng et al. 2019 (setting `all`) for
//! a few foods.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use std::sync::Arc;

use hil_core::config::{EnvironmentConfig, PolicyConfig, WorkloadModelConfig};
use hil_core::policy::{check_feedback, check_input};
use hil_core::{
    ActionSpace, ArmDiagnostics, ArmId, BuildContext, Context, Decision, DecisionInput,
    Diagnostics, Environment, Feedback, HilError, Item, Outcome, Policy, QueryHistory, QueryKind,
    Result, Timestep, WorkloadModel,
};

/// Published success rates (VS0 VS90 TV0 TV90 TA0 TA90) of a few foods.
const FOODS: [(&str, &str, [f64; 6]); 7] = [
    (
        "apple",
        "a slice of apple",
        [0.53, 1.0, 0.57, 0.77, 0.33, 0.77],
    ),
    (
        "banana",
        "a round slice of banana",
        [0.2, 0.2, 0.1, 0.1, 0.57, 0.57],
    ),
    (
        "bell_pepper",
        "a strip of bell pepper",
        [0.77, 0.93, 0.73, 0.77, 0.0, 0.5],
    ),
    (
        "broccoli",
        "a floret of broccoli",
        [0.83, 0.9, 0.93, 0.53, 0.4, 0.3],
    ),
    (
        "cantaloupe",
        "a cube of cantaloupe",
        [0.77, 0.93, 0.7, 0.8, 0.3, 0.27],
    ),
    ("carrot", "a baby carrot", [0.0, 0.53, 0.0, 0.43, 0.0, 0.03]),
    ("grape", "a grape", [0.47, 0.77, 0.53, 0.87, 0.0, 0.37]),
];

/// Config of the demo plate, `type = "demo_plate"`:
///
/// ```toml
/// [environment]
/// type = "demo_plate"
/// foods = ["banana", "carrot", "grape"]   # one item each, in this order
/// repeat = 2                              # the list is served twice
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoPlateConfig {
    /// Foods on the plate, in order (see [`DemoPlate::FOODS`]).
    pub foods: Vec<String>,
    /// How many times the list is served (default 1).
    #[serde(default = "one")]
    pub repeat: usize,
}

fn one() -> usize {
    1
}

#[typetag::serde(name = "demo_plate")]
impl EnvironmentConfig for DemoPlateConfig {
    fn build(&self, _ctx: &BuildContext) -> Result<Box<dyn Environment>> {
        Ok(Box::new(DemoPlate::new(&self.foods, self.repeat)?))
    }
}

/// A plate of foods with published per-action success rates. Contexts are
/// the one-hot code of the food followed by two noise features, so every
/// attempt observes a fresh context; outcomes are seeded Bernoulli draws.
#[derive(Debug, Clone)]
pub struct DemoPlate {
    actions: ActionSpace,
    types: Vec<usize>,
    order: Vec<usize>,
    rng: ChaCha8Rng,
    next: usize,
    current: Option<(Item, usize)>,
    observed: bool,
}

impl DemoPlate {
    /// The foods a demo plate can hold.
    pub const FOODS: [&'static str; 7] = [
        "apple",
        "banana",
        "bell_pepper",
        "broccoli",
        "cantaloupe",
        "carrot",
        "grape",
    ];

    /// A plate serving `foods` (names from [`DemoPlate::FOODS`]) `repeat` times.
    pub fn new(foods: &[String], repeat: usize) -> Result<Self> {
        if foods.is_empty() || repeat == 0 {
            return Err(HilError::invalid_parameter(
                "foods",
                format!("{foods:?} × {repeat}"),
                "the plate needs at least one food, served at least once",
            ));
        }
        let mut order = Vec::new();
        let mut types = Vec::new();
        for f in foods {
            let idx = FOODS.iter().position(|(n, _, _)| n == f).ok_or_else(|| {
                HilError::invalid_parameter(
                    "foods",
                    f,
                    format!("unknown food; choose from {:?}", Self::FOODS),
                )
            })?;
            if !types.contains(&idx) {
                types.push(idx);
            }
            order.push(idx);
        }
        let once = order.clone();
        for _ in 1..repeat {
            order.extend_from_slice(&once);
        }
        Ok(Self {
            actions: ActionSpace::feeding(),
            types,
            order,
            rng: ChaCha8Rng::seed_from_u64(0),
            next: 0,
            current: None,
            observed: false,
        })
    }

    fn food(&self) -> Result<usize> {
        self.current
            .as_ref()
            .map(|(_, f)| *f)
            .ok_or_else(|| HilError::state("demo_plate", "no current item: call next_item first"))
    }
}

impl Environment for DemoPlate {
    fn name(&self) -> &str {
        "demo_plate"
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        self.types.len() + 2
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.current = None;
        self.observed = false;
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        self.observed = false;
        let Some(&food) = self.order.get(self.next) else {
            self.current = None;
            return Ok(None);
        };
        let (label, description, _) = FOODS[food];
        let item = Item {
            index: self.next,
            label: label.into(),
            description: Some(description.into()),
        };
        self.next += 1;
        self.current = Some((item.clone(), food));
        Ok(Some(item))
    }
    fn observe(&mut self) -> Result<Context> {
        let food = self.food()?;
        let mut x: Vec<f64> = self.types.iter().map(|t| f64::from(*t == food)).collect();
        x.push(self.rng.random_range(-0.1..0.1));
        x.push(self.rng.random_range(-0.1..0.1));
        self.observed = true;
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.actions.check(arm)?;
        if !self.observed {
            return Err(HilError::state("demo_plate", "execute before observe"));
        }
        let p = FOODS[self.food()?].2[arm.0];
        Ok(Outcome {
            success: self.rng.random_bool(p),
            success_probability: Some(p),
        })
    }
    fn best_action(&self) -> Option<ArmId> {
        let p = &FOODS[self.food().ok()?].2;
        let mut best = 0;
        for (i, v) in p.iter().enumerate() {
            if *v > p[best] {
                best = i;
            }
        }
        Some(ArmId(best))
    }
    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref().map(|(i, _)| i)
    }
}

/// Config of the demo learner, `type = "demo_learner"`:
///
/// ```toml
/// [policy]
/// type = "demo_learner"
/// query_probability = 0.5   # chance of asking at an item's first attempt
/// epsilon = 0.1             # chance of a random action otherwise
/// kinds = [{ response = "mcq" }, { response = "bounding_box", difficulty = "hard" }]
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoLearnerConfig {
    /// Probability in [0, 1] of asking at the first attempt of an item.
    pub query_probability: f64,
    /// Probability in [0, 1] of a uniformly random action when acting.
    #[serde(default)]
    pub epsilon: f64,
    /// Kinds of query, used in turn (default: one easy MCQ).
    #[serde(default)]
    pub kinds: Vec<QueryKind>,
}

#[typetag::serde(name = "demo_learner")]
impl PolicyConfig for DemoLearnerConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Policy>> {
        for (name, v) in [
            ("query_probability", self.query_probability),
            ("epsilon", self.epsilon),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(HilError::invalid_parameter(
                    name,
                    v,
                    "must be a probability in [0, 1]",
                ));
            }
        }
        let (Some(actions), Some(dim)) = (&ctx.action_space, ctx.context_dim) else {
            return Err(HilError::state(
                "demo_learner",
                "the environment must be built before the policy",
            ));
        };
        Ok(Box::new(DemoLearner::new(actions.len(), dim, self.clone())))
    }
}

/// A small seeded learner: per context feature and arm it keeps a weighted
/// success count, acts greedily on it (with ε-exploration), and asks with a
/// fixed probability at an item's first attempt.
#[derive(Debug, Clone)]
pub struct DemoLearner {
    n_arms: usize,
    dim: usize,
    params: DemoLearnerConfig,
    /// Per arm, per feature: (reward-weighted sum, weight sum).
    stats: Vec<Vec<(f64, f64)>>,
    asked: usize,
    rng: ChaCha8Rng,
}

#[derive(Serialize, Deserialize)]
struct LearnerState {
    stats: Vec<Vec<(f64, f64)>>,
    asked: usize,
    rng_seed: [u8; 32],
    rng_stream: u64,
    /// Decimal: JSON numbers cannot hold a u128.
    rng_word_pos: String,
}

impl DemoLearner {
    /// A learner over `n_arms` arms and `dim`-dimensional contexts.
    pub fn new(n_arms: usize, dim: usize, params: DemoLearnerConfig) -> Self {
        Self {
            n_arms,
            dim,
            params,
            stats: vec![vec![(0.0, 0.0); dim]; n_arms],
            asked: 0,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }

    fn estimate(&self, x: &Context, arm: usize) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for (i, v) in x.as_slice().iter().enumerate() {
            let w = v.abs();
            num += w * self.stats[arm][i].0;
            den += w * self.stats[arm][i].1;
        }
        // Optimistic prior: untried arms look good, so they get tried.
        (num + 1.0) / (den + 1.0)
    }
}

impl Policy for DemoLearner {
    fn name(&self) -> &str {
        "demo_learner"
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        check_input(self, input)?;
        let estimates: Vec<f64> = (0..self.n_arms)
            .map(|a| self.estimate(input.context, a))
            .collect();
        let mut greedy = 0;
        for (a, e) in estimates.iter().enumerate() {
            if *e > estimates[greedy] {
                greedy = a;
            }
        }
        let explore = self.rng.random_bool(self.params.epsilon);
        let random_arm = self.rng.random_range(0..self.n_arms);
        let ask = self.rng.random_bool(self.params.query_probability);
        let arm = ArmId(if explore { random_arm } else { greedy });
        let diagnostics = Diagnostics {
            arms: estimates
                .iter()
                .map(|e| ArmDiagnostics {
                    estimate: *e,
                    bonus: 0.0,
                    ucb: *e,
                })
                .collect(),
            query_probability: Some(if input.attempt == 0 {
                self.params.query_probability
            } else {
                0.0
            }),
            ..Default::default()
        };
        let decision = if input.attempt == 0 && ask {
            let kind = if self.params.kinds.is_empty() {
                QueryKind::default()
            } else {
                self.params.kinds[self.asked % self.params.kinds.len()]
            };
            self.asked += 1;
            Decision::query(kind, arm)
        } else {
            Decision::act(arm)
        };
        Ok(decision.with_diagnostics(diagnostics))
    }
    fn observe(&mut self, f: &Feedback<'_>) -> Result<()> {
        check_feedback(self, f)?;
        for (i, v) in f.context.as_slice().iter().enumerate() {
            let w = v.abs();
            self.stats[f.arm.0][i].0 += w * f.reward;
            self.stats[f.arm.0][i].1 += w;
        }
        Ok(())
    }
    fn save(&self) -> Result<Value> {
        serde_json::to_value(LearnerState {
            stats: self.stats.clone(),
            asked: self.asked,
            rng_seed: self.rng.get_seed(),
            rng_stream: self.rng.get_stream(),
            rng_word_pos: self.rng.get_word_pos().to_string(),
        })
        .map_err(|e| HilError::serde("demo_learner state", e))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let s: LearnerState =
            serde_json::from_value(state).map_err(|e| HilError::serde("demo_learner state", e))?;
        if s.stats.len() != self.n_arms || s.stats.iter().any(|r| r.len() != self.dim) {
            return Err(HilError::state(
                "demo_learner",
                format!(
                    "checkpoint shape does not match {} arms × d = {}",
                    self.n_arms, self.dim
                ),
            ));
        }
        let word_pos: u128 = s
            .rng_word_pos
            .parse()
            .map_err(|e| HilError::serde("demo_learner state field `rng_word_pos`", e))?;
        self.stats = s.stats;
        self.asked = s.asked;
        let mut rng = ChaCha8Rng::from_seed(s.rng_seed);
        rng.set_stream(s.rng_stream);
        rng.set_word_pos(word_pos);
        self.rng = rng;
        Ok(())
    }
}

/// Config of the demo workload model, `type = "demo_counting"`:
///
/// ```toml
/// [workload]
/// type = "demo_counting"
/// increment = 0.05   # each query in the window adds this
/// window = 10        # timesteps a query keeps counting (H)
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoCounting {
    /// Workload added per query in the window, in [0, 1].
    pub increment: f64,
    /// Number of timesteps a query counts for (at least 1).
    pub window: u64,
}

#[typetag::serde(name = "demo_counting")]
impl WorkloadModelConfig for DemoCounting {
    fn build(&self, _ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>> {
        if !(0.0..=1.0).contains(&self.increment) {
            return Err(HilError::invalid_parameter(
                "increment",
                self.increment,
                "must be in [0, 1]",
            ));
        }
        if self.window == 0 {
            return Err(HilError::invalid_parameter(
                "window",
                0,
                "must be at least 1",
            ));
        }
        Ok(Arc::new(*self))
    }
}

/// WL_t = clamp(WL_0 + increment · (queries in the last `window` steps), 0, 1).
impl WorkloadModel for DemoCounting {
    fn name(&self) -> &str {
        "demo_counting"
    }
    fn predict(&self, wl0: f64, history: &QueryHistory, t: Timestep) -> Result<f64> {
        let n = history.recent(t, self.window).count();
        Ok((wl0 + self.increment * n as f64).clamp(0.0, 1.0))
    }
}
