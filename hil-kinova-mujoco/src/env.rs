//! [`KinovaFeedingEnv`]: the MuJoCo feeding simulation as a
//! `hil_core::Environment`, and its config type `kinova_feeding`.
//!
//! ```
//! use hil_core::Environment;
//! use hil_kinova_mujoco::{KinovaFeedingConfig, KinovaFeedingEnv};
//!
//! let mut env = KinovaFeedingEnv::new(KinovaFeedingConfig::default())?;
//! env.reset(7)?;
//! while let Some(item) = env.next_item()? {
//!     let x = env.observe()?;
//!     let out = env.execute(hil_core::ArmId(4))?; // TA0
//!     println!("{}: {} (context dim {})", item.label, out.success, x.dim());
//! }
//! # Ok::<(), hil_core::HilError>(())
//! ```

use std::path::PathBuf;
use std::sync::Arc;

use hil_config::{BuildContext, EnvironmentConfig, ExpertRate};
use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Environment, HilError, Item, LabelledObservation,
    Outcome, Result,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::controller::{RollBy, actions};
use crate::food::{FoodKind, FoodProps, Setting, parse_labels};
use crate::food_models::FoodModels;
use crate::model::MjcfSource;
use crate::perception::{Embedding, Observation, PerceptionNoise, RIM_RADIUS, perceive};
use crate::sim::{AttemptReport, KeyframeHook, LeafPlacement, Placement, Simulator};

/// Configuration of [`KinovaFeedingEnv`] (`type = "kinova_feeding"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KinovaFeedingConfig {
    /// The items of one episode, in order (`banana`, `carrot`, `cantaloupe`).
    #[serde(default = "default_plate")]
    pub plate: Vec<String>,
    /// Dimension of the contexts, at most
    /// [`hil_config::limits::CONTEXT_DIM`].
    #[serde(default = "default_dim")]
    pub context_dim: usize,
    /// Seed of the fixed feature embedding.
    #[serde(default)]
    pub embedding_seed: u64,
    /// Settings an item may be placed in (`isolated`, `wall`, `lettuce`);
    /// each item draws one uniformly.
    #[serde(default = "default_settings")]
    pub settings: Vec<String>,
    /// Place the episode's other remaining items on the plate too.
    #[serde(default = "yes")]
    pub neighbours: bool,
    /// A custom scene (MJCF) instead of the built-in one.
    #[serde(default)]
    pub mjcf: Option<PathBuf>,
    /// A food-models file changing the built-in food mechanics (see
    /// [`FoodModels`](crate::FoodModels)), resolved like `mjcf`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub food_models: Option<PathBuf>,
    /// Perception noise.
    #[serde(default)]
    pub noise: PerceptionNoise,
    /// Simulated attempts per (food, action) offered to policies as
    /// pretraining data (`pretrain = true` in their configs); 0 offers none.
    /// They run on a separate seed stream, on `pretrain_foods`.
    #[serde(default)]
    pub pretraining_trials: usize,
    /// The foods of the pretraining attempts, each alone on the plate in
    /// one of `settings`. Empty (the default): the plate's own foods. The
    /// paper pretrained on foods not on the plate: name derived kinds
    /// (`honeydew`, `kiwi`, `celery`; see [`FoodKind`]).
    #[serde(default)]
    pub pretrain_foods: Vec<String>,
    /// How long an item must stay on the lifted fork to count (s); the
    /// published rule is 5 s.
    #[serde(default = "default_hold")]
    pub hold_s: f64,
    /// The tool and what turns the tine row by an action's roll:
    /// `fork_gamma` (default: the study's 2-DoF fork, its γ joint, its own
    /// yielding servos) or `arm_yaw` (the published data set's rigid fork,
    /// turned by the arm).
    #[serde(default)]
    pub roll_by: RollBy,
}

fn default_hold() -> f64 {
    hil_paper::food_data::HOLD_SECONDS
}

fn default_plate() -> Vec<String> {
    FoodKind::SCENE
        .iter()
        .map(|k| k.name().to_string())
        .collect()
}
fn default_settings() -> Vec<String> {
    Setting::ALL.iter().map(|k| k.name().to_string()).collect()
}
fn default_dim() -> usize {
    32
}
fn yes() -> bool {
    true
}

impl Default for KinovaFeedingConfig {
    fn default() -> Self {
        Self {
            plate: default_plate(),
            context_dim: default_dim(),
            embedding_seed: 0,
            settings: default_settings(),
            neighbours: true,
            mjcf: None,
            food_models: None,
            noise: PerceptionNoise::default(),
            pretraining_trials: 0,
            pretrain_foods: Vec::new(),
            hold_s: hil_paper::food_data::HOLD_SECONDS,
            roll_by: RollBy::default(),
        }
    }
}

impl KinovaFeedingConfig {
    fn foods(&self) -> Result<Vec<FoodKind>> {
        parse_labels("plate", &self.plate)
    }

    /// The foods of the pretraining attempts (the plate's when none are named).
    fn pretraining_foods(&self) -> Result<Vec<FoodKind>> {
        if self.pretrain_foods.is_empty() {
            self.foods()
        } else {
            parse_labels("pretrain_foods", &self.pretrain_foods)
        }
    }

    fn parsed_settings(&self) -> Result<Vec<Setting>> {
        parse_labels("settings", &self.settings)
    }
}

impl KinovaFeedingEnv {
    /// The scene `config` describes when it is a `kinova_feeding` config
    /// (found by its `type` key), built with its paths resolved from `ctx`;
    /// `None` for any other environment. A caller that needs the concrete
    /// scene, e.g. to record keyframes around its attempts, gets it here
    /// rather than as the boxed `dyn Environment` the config builds.
    pub fn from_component(
        config: &dyn EnvironmentConfig,
        ctx: &BuildContext,
    ) -> Result<Option<Self>> {
        let mut value =
            serde_json::to_value(config).map_err(|e| HilError::serde("environment", e))?;
        let Some(table) = value.as_object_mut() else {
            return Ok(None);
        };
        if table.get("type").and_then(serde_json::Value::as_str) != Some("kinova_feeding") {
            return Ok(None);
        }
        table.remove("type");
        let scene: KinovaFeedingConfig =
            serde_json::from_value(value).map_err(|e| HilError::serde("environment", e))?;
        Self::new(scene.resolved(ctx)).map(Some)
    }
}

impl KinovaFeedingConfig {
    /// This config with a custom scene (`mjcf`) resolved against the
    /// config file's directory, as every build from `ctx` needs it.
    pub fn resolved(&self, ctx: &BuildContext) -> Self {
        let mut cfg = self.clone();
        cfg.mjcf = cfg.mjcf.map(|p| ctx.resolve(&p));
        cfg.food_models = cfg.food_models.map(|p| ctx.resolve(&p));
        cfg
    }
}

/// Most `pretraining_trials` per (food, action) a Kinova config may ask for.
pub const MAX_PRETRAINING_TRIALS: u64 = 10_000;

#[typetag::serde(name = "kinova_feeding")]

impl EnvironmentConfig for KinovaFeedingConfig {
    /// Every check of the config, run when a config file is loaded (so an
    /// error names the file, line and field) and again by
    /// [`KinovaFeedingEnv::new`].
    fn validate(&self) -> Result<()> {
        use hil_config::limits::{CONTEXT_DIM, ITEMS_PER_EPISODE, check_at_most, check_count};
        check_count("plate", self.plate.len(), ITEMS_PER_EPISODE)?;
        check_count("context_dim", self.context_dim, CONTEXT_DIM)?;
        check_at_most("settings", self.settings.len(), ITEMS_PER_EPISODE)?;
        check_at_most(
            "pretrain_foods",
            self.pretrain_foods.len(),
            ITEMS_PER_EPISODE,
        )?;
        check_at_most(
            "pretraining_trials",
            self.pretraining_trials,
            MAX_PRETRAINING_TRIALS,
        )?;
        self.foods()?;
        self.pretraining_foods()?;
        self.parsed_settings()?;
        let n = &self.noise;
        for (name, v) in [
            ("noise.position_m", n.position_m),
            ("noise.yaw_rad", n.yaw_rad),
            ("noise.size_rel", n.size_rel),
            ("noise.colour", n.colour),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(HilError::invalid_parameter(
                    name,
                    v.to_string(),
                    "must be finite and ≥ 0",
                ));
            }
        }
        crate::sim::check_hold(self.hold_s)
            .map_err(|e| HilError::invalid_parameter("hold_s", self.hold_s, e.to_string()))
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Environment>> {
        // `new` validates.
        Ok(Box::new(KinovaFeedingEnv::new(self.resolved(ctx))?))
    }

    fn pretraining(&self, ctx: &BuildContext) -> Result<Option<Arc<[LabelledObservation]>>> {
        if self.pretraining_trials == 0 {
            return Ok(None);
        }
        Ok(Some(
            simulated_pretraining(&self.resolved(ctx), ctx.seed)?.into(),
        ))
    }

    /// The plate's foods with the action the simulated expert names (the
    /// best published one, [`FoodKind::expert_action`]) and its published
    /// rate averaged over `settings`, from which every item draws one
    /// uniformly. The rates are those of the published data set's tool,
    /// whatever `roll_by` says.
    fn published_expert_rates(&self) -> Result<Option<Vec<ExpertRate>>> {
        let settings = self.parsed_settings()?;
        let rates = self
            .foods()?
            .into_iter()
            .map(|kind| {
                let a = kind.expert_action();
                let rate = settings
                    .iter()
                    .map(|&s| kind.published_rates_in(s)[a])
                    .sum::<f64>()
                    / settings.len() as f64;
                ExpertRate {
                    item: kind.name().to_string(),
                    action: actions()[a].name.to_string(),
                    rate,
                }
            })
            .collect();
        Ok(Some(rates))
    }
}

/// Seed stream of pretraining attempts (kept apart from episode seeds).
const PRETRAIN_STREAM: u64 = 0x7072_6574_7261_696e;

/// Runs `cfg.pretraining_trials` attempts of every action on every distinct
/// food of `cfg.pretrain_foods` (default: the plate's) and returns them as
/// labelled observations.
pub fn simulated_pretraining(
    cfg: &KinovaFeedingConfig,
    seed: u64,
) -> Result<Vec<LabelledObservation>> {
    let mut foods = cfg.pretraining_foods()?;
    foods.sort();
    foods.dedup();
    let models = FoodModels::from_file(cfg.food_models.as_deref())?;
    let mut out = Vec::new();
    for food in foods {
        let scene = KinovaFeedingConfig {
            plate: vec![food.name().to_string()],
            neighbours: false,
            pretraining_trials: 0,
            ..cfg.clone()
        };
        let mut env = KinovaFeedingEnv::with_models(scene, models.clone())?;
        for arm in 0..actions().len() {
            for t in 0..cfg.pretraining_trials {
                let stream = (food.index() * actions().len() + arm) * cfg.pretraining_trials + t;
                env.reset(hil_core::session::splitmix(
                    seed ^ PRETRAIN_STREAM,
                    stream as u64,
                ))?;
                env.next_item()?;
                let context = env.observe()?;
                let reward = env.execute(ArmId(arm))?.reward();
                out.push(LabelledObservation {
                    context,
                    arm: ArmId(arm),
                    reward,
                });
            }
        }
    }
    Ok(out)
}

#[derive(Debug)]
struct Current {
    item: Item,
    props: FoodProps,
    setting: Setting,
    observation: Option<Observation>,
}

/// The Kinova Gen3 feeding simulation as an [`Environment`].
///
/// Each item is a freshly drawn piece of the configured food in a setting
/// drawn from `settings` (isolated, against the rim, on lettuce); each
/// `observe` places it (and the episode's remaining items) on the plate,
/// lets them settle and perceives the target; `execute` runs the
/// action through the controller and physics. `best_action` is the
/// published best action for the food (what an informed caregiver names).
#[derive(Debug)]
pub struct KinovaFeedingEnv {
    cfg: KinovaFeedingConfig,
    foods: Vec<FoodKind>,
    settings: Vec<Setting>,
    models: FoodModels,
    sim: Simulator,
    embedding: Embedding,
    actions: ActionSpace,
    rng: ChaCha8Rng,
    cursor: usize,
    current: Option<Current>,
    last: Option<AttemptReport>,
    calls: CallOrder,
}

impl KinovaFeedingEnv {
    /// Builds the environment (loads the MJCF and the food-models file).
    pub fn new(cfg: KinovaFeedingConfig) -> Result<Self> {
        let models = FoodModels::from_file(cfg.food_models.as_deref())?;
        Self::with_models(cfg, models)
    }

    /// Builds the environment with food models already read from
    /// `cfg.food_models`, so that a caller building many scenes from one
    /// config reads the file once.
    pub(crate) fn with_models(cfg: KinovaFeedingConfig, models: FoodModels) -> Result<Self> {
        EnvironmentConfig::validate(&cfg)?;
        let mut sim = match &cfg.mjcf {
            Some(p) => Simulator::from_source(MjcfSource::File(p))?,
            None => Simulator::new()?,
        };
        sim.set_hold(cfg.hold_s).map_err(|e| {
            HilError::invalid_parameter("hold_s", cfg.hold_s.to_string(), e.to_string())
        })?;
        sim.set_roll_by(cfg.roll_by);
        Ok(Self {
            foods: cfg.foods()?,
            settings: cfg.parsed_settings()?,
            models,
            embedding: Embedding::new(cfg.context_dim, cfg.embedding_seed),
            sim,
            actions: hil_envs::feeding::action_space(),
            rng: ChaCha8Rng::seed_from_u64(0),
            cursor: 0,
            current: None,
            last: None,
            calls: CallOrder::new("kinova_feeding"),
            cfg,
        })
    }

    /// The simulator (for rendering and timing).
    pub fn simulator(&self) -> &Simulator {
        &self.sim
    }

    /// The setting of the current item.
    pub fn current_setting(&self) -> Option<Setting> {
        self.current.as_ref().map(|c| c.setting)
    }

    /// Details of the last executed attempt.
    pub fn last_attempt(&self) -> Option<&AttemptReport> {
        self.last.as_ref()
    }

    /// Like [`Environment::execute`], calling `keyframe` at each phase.
    pub fn execute_with(
        &mut self,
        arm: ArmId,
        keyframe: Option<KeyframeHook<'_>>,
    ) -> Result<Outcome> {
        self.actions.check(arm)?;
        self.calls.on_execute()?;
        let cur = self
            .current
            .as_mut()
            .ok_or_else(|| HilError::state("kinova_feeding", "execute called before next_item"))?;
        let obs = cur.observation.take().ok_or_else(|| {
            HilError::state("kinova_feeding", "execute called without a fresh observe")
        })?;
        let report = self.sim.execute(&actions()[arm.0], &obs.target, keyframe)?;
        let success = report.success;
        self.last = Some(report);
        Ok(Outcome::new(success))
    }

    /// Lays out the plate for `target` in `setting`: the target first,
    /// then (with `neighbours`) the episode's remaining items where they fit
    /// clear of it, of the leaf and of the rim; a neighbour with no free
    /// spot after 200 draws is left off the plate.
    fn place(
        &mut self,
        target: &FoodProps,
        setting: Setting,
    ) -> (Vec<Placement>, Option<LeafPlacement>) {
        use std::f64::consts::{PI, TAU};
        let rng = &mut self.rng;
        let mut leaf = None;
        let reach = target.shape.half_extents()[0];
        let angle = rng.random_range(0.0..TAU);
        let first = match setting {
            Setting::Isolated => {
                let rad =
                    (RIM_RADIUS - reach - ISOLATED_CLEARANCE).max(0.0) * rng.random::<f64>().sqrt();
                let yaw = rng.random_range(-PI..PI);
                Placement {
                    props: target.clone(),
                    xy: [rad * angle.cos(), rad * angle.sin()],
                    yaw,
                }
            }
            Setting::Wall => {
                let [hx, hy, _] = target.shape.half_extents();
                // An elongated item lies along the rim; others at any yaw.
                let yaw = if hx > 1.3 * hy {
                    angle + PI / 2.0 + 0.15 * rng.random_range(-1.0..1.0)
                } else {
                    rng.random_range(-PI..PI)
                };
                let d = yaw - angle;
                let radial = match target.shape {
                    crate::food::Shape::Disc { radius, .. } => radius,
                    _ => hx * d.cos().abs() + hy * d.sin().abs(),
                };
                let rad = RIM_RADIUS - radial - 0.001;
                Placement {
                    props: target.clone(),
                    xy: [rad * angle.cos(), rad * angle.sin()],
                    yaw,
                }
            }
            Setting::Lettuce => {
                let rad = (RIM_RADIUS - LEAF_REACH - 0.004) * rng.random::<f64>().sqrt();
                let xy = [rad * angle.cos(), rad * angle.sin()];
                leaf = Some(LeafPlacement {
                    xy,
                    yaw: rng.random_range(-PI..PI),
                    under: target.kind,
                });
                Placement {
                    props: target.clone(),
                    xy,
                    yaw: rng.random_range(-PI..PI),
                }
            }
        };
        // Keep-out discs: (centre, radius).
        let mut taken = vec![(first.xy, if leaf.is_some() { LEAF_REACH } else { reach })];
        let mut placed = vec![first];
        if self.cfg.neighbours {
            for &k in &self.foods[self.cursor..] {
                // One body per calibrated kind: a neighbour sharing the
                // target's body (honeydew beside cantaloupe) stays off.
                if placed.iter().any(|p| p.props.kind.slot() == k.slot()) {
                    continue;
                }
                let props = self.models.get(k).sample(rng);
                let r = props.shape.half_extents()[0];
                for _ in 0..200 {
                    let rad = (RIM_RADIUS - r - 0.003).max(0.0) * rng.random::<f64>().sqrt();
                    let a = rng.random_range(0.0..TAU);
                    let xy = [rad * a.cos(), rad * a.sin()];
                    let clear = taken.iter().all(|(c, cr)| {
                        ((c[0] - xy[0]).powi(2) + (c[1] - xy[1]).powi(2)).sqrt() > r + cr + 0.006
                    });
                    if clear {
                        taken.push((xy, r));
                        placed.push(Placement {
                            props,
                            xy,
                            yaw: rng.random_range(-PI..PI),
                        });
                        break;
                    }
                }
            }
        }
        (placed, leaf)
    }
}

/// An isolated item keeps at least this far from the rim (m).
const ISOLATED_CLEARANCE: f64 = 0.02;
/// Radius of the disc the lettuce leaf covers, whatever its yaw (m).
const LEAF_REACH: f64 = 0.044;

impl Environment for KinovaFeedingEnv {
    fn name(&self) -> &str {
        "kinova_feeding"
    }

    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }

    fn context_dim(&self) -> usize {
        self.embedding.dim()
    }

    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.cursor = 0;
        self.current = None;
        self.last = None;
        self.calls.on_reset();
        Ok(())
    }

    fn next_item(&mut self) -> Result<Option<Item>> {
        let Some(&kind) = self.foods.get(self.cursor) else {
            self.current = None;
            self.calls.on_next_item(false);
            return Ok(None);
        };
        let props = self.models.get(kind).sample(&mut self.rng);
        let setting = self.settings[self.rng.random_range(0..self.settings.len())];
        let item = Item::new(self.cursor, kind.name().to_string()).with_description(format!(
            "{} {}",
            kind.description(),
            setting.description()
        ));
        self.cursor += 1;
        self.current = Some(Current {
            item: item.clone(),
            props,
            setting,
            observation: None,
        });
        self.calls.on_next_item(true);
        Ok(Some(item))
    }

    fn observe(&mut self) -> Result<Context> {
        self.calls.on_observe()?;
        let (props, setting) = match &self.current {
            Some(c) => (c.props.clone(), c.setting),
            None => {
                return Err(HilError::state(
                    "kinova_feeding",
                    "observe called before next_item",
                ));
            }
        };
        // Items already eaten are gone; the current one is `cursor - 1`.
        self.cursor -= 1;
        let (placed, leaf) = self.place(&props, setting);
        self.cursor += 1;
        let poses = self.sim.stage(&placed, leaf, props.kind)?;
        let target = poses
            .iter()
            .position(|p| p.kind == props.kind)
            .ok_or_else(|| HilError::state("kinova_feeding", "target missing after staging"))?;
        let plate = self.sim.plate_top_centre();
        let obs = perceive(
            &poses,
            target,
            &props.shape,
            props.colour,
            [plate.x, plate.y, plate.z],
            &self.cfg.noise,
            &mut self.rng,
        );
        let x = Context::new(self.embedding.embed(&obs.raw))?;
        if let Some(c) = self.current.as_mut() {
            c.observation = Some(obs);
        }
        Ok(x)
    }

    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.execute_with(arm, None)
    }

    fn best_action(&self) -> Option<ArmId> {
        self.current
            .as_ref()
            .map(|c| ArmId(c.props.kind.expert_action()))
    }

    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref().map(|c| &c.item)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_expert_rates_are_the_published_ones_where_the_items_lie() {
        // The paper's study: every item isolated.
        let isolated = KinovaFeedingConfig {
            settings: vec!["isolated".into()],
            ..KinovaFeedingConfig::default()
        };
        let rates = isolated.published_expert_rates().unwrap().unwrap();
        let got: Vec<(&str, &str, f64)> = rates
            .iter()
            .map(|r| (r.item.as_str(), r.action.as_str(), r.rate))
            .collect();
        assert_eq!(
            got,
            [
                ("banana", "TA0", 0.2),
                ("carrot", "VS90", 1.0),
                ("cantaloupe", "VS90", 1.0)
            ]
        );
        // Every setting: the mean of the three, the published `all` row.
        let all = KinovaFeedingConfig::default()
            .published_expert_rates()
            .unwrap()
            .unwrap();
        for r in &all {
            let kind = FoodKind::parse(&r.item).unwrap();
            let pooled = kind.published_rates()[kind.expert_action()];
            assert!((r.rate - pooled).abs() < 0.006, "{r:?} vs {pooled}");
        }
        // A bad setting is the config's error, not a silent default.
        let bad = KinovaFeedingConfig {
            settings: vec!["table".into()],
            ..KinovaFeedingConfig::default()
        };
        assert!(matches!(
            bad.published_expert_rates(),
            Err(HilError::InvalidParameter { .. })
        ));
    }
}
