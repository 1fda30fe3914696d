//! [`DatasetReplayEnv`]: the paper's simulated testbed over a food dataset.

use std::path::PathBuf;
use std::sync::Arc;

use hil_config::{BuildContext, EnvironmentConfig, limits};
use hil_core::session::splitmix;
use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Environment, HilError, Item, LabelledObservation,
    Outcome, Result,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::dataset::FoodDataset;
use crate::split::check_disjoint;

/// How `execute` decides success.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutcomeMode {
    /// Bernoulli(s(x, a)).
    #[default]
    Sample,
    /// A recorded trial of (image, action), picked at random; an error if the
    /// dataset has no recorded outcomes.
    Replay,
}

/// The paper's simulated testbed: an episode is a random sequence of food
/// items from a list of foods; every attempt draws a fresh random image of
/// the current food, and an action succeeds with the image's success
/// probability s(x, a) (or as a recorded trial says). The simulated expert's
/// answer is [`Environment::best_action`] = argmax_a s(x, a).
///
/// Randomness is common across policies: the image and the uniform number
/// deciding success at attempt k of item i depend only on the seed, i and k,
/// so two policies reset with the same seed face the same images and the same
/// luck whenever they make the same number of attempts.
///
/// ```
/// use hil_core::{ArmId, Environment};
/// use hil_envs::DatasetReplayEnv;
/// let ds = hil_envs::bundled_dataset().unwrap();
/// let mut env = DatasetReplayEnv::new(ds, &["banana".into(), "carrot".into()], 5).unwrap();
/// env.reset(1).unwrap();
/// let item = env.next_item().unwrap().unwrap();
/// let x = env.observe().unwrap();
/// assert_eq!(x.dim(), 2048);
/// let best = env.best_action().unwrap();
/// let out = env.execute(best).unwrap();
/// assert!(out.success_probability.unwrap() >= 0.0);
/// ```
#[derive(Clone, Debug)]
pub struct DatasetReplayEnv {
    dataset: Arc<FoodDataset>,
    foods: Vec<usize>,
    items_per_episode: usize,
    mode: OutcomeMode,
    seed: u64,
    sequence: Vec<usize>,
    next: usize,
    current: Option<Item>,
    attempt: u64,
    /// The image and uniform draw of the last observation, until executed.
    observed: Option<(usize, f64)>,
    last_image: Option<usize>,
    calls: CallOrder,
}

impl DatasetReplayEnv {
    /// An environment presenting `items_per_episode` items (at most
    /// [`limits::ITEMS_PER_EPISODE`]) drawn uniformly (with replacement) from
    /// `foods` of `dataset`.
    pub fn new(
        dataset: Arc<FoodDataset>,
        foods: &[String],
        items_per_episode: usize,
    ) -> Result<Self> {
        check_items(items_per_episode)?;
        check_disjoint(&[("foods", foods)], &dataset)?;
        let foods = foods
            .iter()
            .map(|f| dataset.food_index(f).expect("checked above"))
            .collect();
        Ok(Self {
            dataset,
            foods,
            items_per_episode,
            mode: OutcomeMode::Sample,
            seed: 0,
            sequence: Vec::new(),
            next: 0,
            current: None,
            attempt: 0,
            observed: None,
            last_image: None,
            calls: CallOrder::new("food_replay"),
        })
    }

    /// Sets how outcomes are decided; `Replay` needs recorded outcomes for
    /// every image of the environment's foods.
    pub fn with_outcomes(mut self, mode: OutcomeMode) -> Result<Self> {
        if mode == OutcomeMode::Replay {
            for &f in &self.foods {
                let food = &self.dataset.foods[f];
                if let Some(i) = food.images.iter().position(|i| i.outcomes.is_none()) {
                    return Err(HilError::invalid_input(
                        format!("food `{}` image {}", food.name, i + 1),
                        "outcomes = \"replay\" needs recorded outcomes, and this image has none",
                    ));
                }
            }
        }
        self.mode = mode;
        Ok(self)
    }

    /// The dataset.
    pub fn dataset(&self) -> &Arc<FoodDataset> {
        &self.dataset
    }

    /// Index (within its food) of the image last observed.
    pub fn last_image(&self) -> Option<usize> {
        self.last_image
    }

    fn current_food(&self) -> Result<usize> {
        match &self.current {
            Some(item) => Ok(self.sequence[item.index]),
            None => Err(HilError::state(
                self.name().to_string(),
                "no current item: call reset and next_item first",
            )),
        }
    }
}

impl Environment for DatasetReplayEnv {
    fn name(&self) -> &str {
        "food_replay"
    }

    fn action_space(&self) -> &ActionSpace {
        &self.dataset.actions
    }

    fn context_dim(&self) -> usize {
        self.dataset.context_dim
    }

    fn reset(&mut self, seed: u64) -> Result<()> {
        self.seed = seed;
        let mut rng = ChaCha8Rng::seed_from_u64(splitmix(seed, 0));
        self.sequence = (0..self.items_per_episode)
            .map(|_| self.foods[rng.random_range(0..self.foods.len())])
            .collect();
        self.next = 0;
        self.current = None;
        self.observed = None;
        self.last_image = None;
        self.calls.on_reset();
        Ok(())
    }

    fn next_item(&mut self) -> Result<Option<Item>> {
        self.observed = None;
        if self.next >= self.sequence.len() {
            self.current = None;
            self.calls.on_next_item(false);
            return Ok(None);
        }
        let item = Item::new(
            self.next,
            self.dataset.foods[self.sequence[self.next]].name.clone(),
        );
        self.next += 1;
        self.attempt = 0;
        self.current = Some(item.clone());
        self.calls.on_next_item(true);
        Ok(Some(item))
    }

    fn observe(&mut self) -> Result<Context> {
        self.calls.on_observe()?;
        let f = self.current_food()?;
        let index = self.current.as_ref().map_or(0, |i| i.index) as u64;
        // One stream per (item, attempt): common random numbers across policies.
        let mut rng =
            ChaCha8Rng::seed_from_u64(splitmix(self.seed, 1 + (index << 20) + self.attempt));
        self.attempt += 1;
        let images = &self.dataset.foods[f].images;
        let i = rng.random_range(0..images.len());
        let u: f64 = rng.random();
        self.observed = Some((i, u));
        self.last_image = Some(i);
        Ok(images[i].context.clone())
    }

    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.dataset.actions.check(arm)?;
        self.calls.on_execute()?;
        let f = self.current_food()?;
        let (i, u) = self.observed.take().ok_or_else(|| {
            HilError::state(
                "food_replay",
                "execute before observe: observe the item first",
            )
        })?;
        let img = &self.dataset.foods[f].images[i];
        let p = img.success[arm.0];
        let success = match (self.mode, &img.outcomes) {
            (OutcomeMode::Sample, _) => u < p,
            (OutcomeMode::Replay, Some(o)) => {
                let trials = &o[arm.0];
                trials[((u * trials.len() as f64) as usize).min(trials.len() - 1)]
            }
            (OutcomeMode::Replay, None) => {
                return Err(HilError::state(
                    "food_replay",
                    format!(
                        "image {} of `{}` has no recorded outcomes",
                        i + 1,
                        self.dataset.foods[f].name
                    ),
                ));
            }
        };
        Ok(Outcome::new(success).with_success_probability(p))
    }

    fn best_action(&self) -> Option<ArmId> {
        let f = self.current_food().ok()?;
        let i = self.last_image?;
        Some(self.dataset.foods[f].images[i].best_action())
    }

    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref()
    }
}

/// How pretraining rewards are made from the dataset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PretrainReward {
    /// The success probability s(x, a) itself (a soft label, as SPANet is
    /// trained to predict success rates).
    #[default]
    Probability,
    /// One Bernoulli(s(x, a)) draw per (image, action), seeded.
    Sampled,
    /// Every recorded trial of (image, action) as its own observation.
    Recorded,
}

/// The (context, arm, reward) triples of every image of `foods` and every
/// action: the offline data LinUCB-family policies are pretrained on.
///
/// ```
/// use hil_envs::env::{pretraining_data, PretrainReward};
/// let ds = hil_envs::bundled_dataset().unwrap();
/// let data = pretraining_data(&ds, &["apple".into()], PretrainReward::Probability, 0).unwrap();
/// assert_eq!(data.len(), 30 * 6);
/// ```
pub fn pretraining_data(
    ds: &FoodDataset,
    foods: &[String],
    reward: PretrainReward,
    seed: u64,
) -> Result<Vec<LabelledObservation>> {
    check_disjoint(&[("pretrain_foods", foods)], ds)?;
    let mut rng = ChaCha8Rng::seed_from_u64(splitmix(seed, 77));
    let mut out = Vec::new();
    for name in foods {
        let food = ds.food(name)?;
        for (i, img) in food.images.iter().enumerate() {
            for (a, &p) in img.success.iter().enumerate() {
                let mut push = |r: f64| {
                    out.push(LabelledObservation {
                        context: img.context.clone(),
                        arm: ArmId(a),
                        reward: r,
                    })
                };
                match reward {
                    PretrainReward::Probability => push(p),
                    PretrainReward::Sampled => {
                        push(if rng.random::<f64>() < p { 1.0 } else { 0.0 })
                    }
                    PretrainReward::Recorded => {
                        let o = img.outcomes.as_ref().ok_or_else(|| {
                            HilError::invalid_input(
                                format!("food `{name}` image {}", i + 1),
                                "pretrain_reward = \"recorded\" needs recorded outcomes",
                            )
                        })?;
                        for &s in &o[a] {
                            push(if s { 1.0 } else { 0.0 });
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Config (`type = "food_replay"`) of a [`DatasetReplayEnv`]:
///
/// ```toml
/// [environment]
/// type = "food_replay"
/// dataset = "path/to/dataset"    # optional; the bundled synthetic dataset if absent
/// foods = ["banana", "carrot"]   # foods presented in episodes
/// pretrain_foods = ["apple", "kiwi"]  # offered to policies for pretraining
/// items_per_episode = 5
/// outcomes = "sample"            # or "replay" (recorded trials)
/// pretrain_reward = "probability"  # or "sampled", "recorded"
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoodReplayConfig {
    /// Dataset directory (or its manifest); the bundled dataset if absent.
    #[serde(default)]
    pub dataset: Option<PathBuf>,
    /// Foods presented in episodes.
    pub foods: Vec<String>,
    /// Foods whose data is offered for pretraining (none if empty).
    #[serde(default)]
    pub pretrain_foods: Vec<String>,
    /// Items per episode (default 5, at most
    /// [`limits::ITEMS_PER_EPISODE`]).
    #[serde(default = "default_items")]
    pub items_per_episode: usize,
    /// How outcomes are decided.
    #[serde(default)]
    pub outcomes: OutcomeMode,
    /// How pretraining rewards are made.
    #[serde(default)]
    pub pretrain_reward: PretrainReward,
}

fn default_items() -> usize {
    5
}

/// The one check of an episode's item count: it sizes the episode's
/// sequence, so it is bounded by [`limits::ITEMS_PER_EPISODE`].
fn check_items(items_per_episode: usize) -> Result<()> {
    limits::check_count(
        "items_per_episode",
        items_per_episode,
        limits::ITEMS_PER_EPISODE,
    )
}

impl FoodReplayConfig {
    fn dataset(&self, ctx: &BuildContext) -> Result<Arc<FoodDataset>> {
        let ds = match &self.dataset {
            // Named as the config's `dataset` key, so that the error says
            // which config pointed at the file.
            Some(p) => Arc::new(FoodDataset::load(&ctx.resolve(p)).map_err(|e| {
                HilError::invalid_parameter("dataset", p.display(), format!("cannot be used: {e}"))
            })?),
            None => crate::bundled_dataset()?,
        };
        let mut sets: Vec<(&str, &[String])> = vec![("foods", &self.foods)];
        if !self.pretrain_foods.is_empty() {
            sets.push(("pretrain_foods", &self.pretrain_foods));
        }
        check_disjoint(&sets, &ds)?;
        Ok(ds)
    }
}

#[typetag::serde(name = "food_replay")]
impl EnvironmentConfig for FoodReplayConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Environment>> {
        let ds = self.dataset(ctx)?;
        Ok(Box::new(
            DatasetReplayEnv::new(ds, &self.foods, self.items_per_episode)?
                .with_outcomes(self.outcomes)?,
        ))
    }

    fn validate(&self) -> Result<()> {
        check_items(self.items_per_episode)
    }

    fn pretraining(&self, ctx: &BuildContext) -> Result<Option<Arc<[LabelledObservation]>>> {
        if self.pretrain_foods.is_empty() {
            return Ok(None);
        }
        let ds = self.dataset(ctx)?;
        Ok(Some(
            pretraining_data(&ds, &self.pretrain_foods, self.pretrain_reward, ctx.seed)?.into(),
        ))
    }
}
