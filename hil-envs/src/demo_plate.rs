//! A small plate of foods for trying the channels and the interaction
//! record without a robot (`type = "demo_plate"`).
//!
//! It is deliberately simple and is not the paper's testbed (that is
//! [`crate::DatasetReplayEnv`]). The success rates are the published pooled
//! rates of the [`feeding`](crate::feeding) data, and each item carries that
//! data's description for human channels.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use hil_config::BuildContext;
use hil_config::{EnvironmentConfig, limits};
use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Environment, HilError, Item, Outcome, Result,
};

use crate::feeding::{ALL_SETTINGS, FeedingTask, FoodFacts};

/// Config of the demo plate, `type = "demo_plate"`:
///
/// ```toml
/// [environment]
/// type = "demo_plate"
/// foods = ["banana", "carrot", "grape"]   # one item each, in this order
/// repeat = 2                              # the list is served twice
/// ```
///
/// ```
/// use hil_config::EnvironmentConfig;
/// let cfg = hil_envs::demo_plate::DemoPlateConfig { foods: vec!["grape".into()], repeat: 2 };
/// let env = cfg.build(&hil_config::BuildContext::new(".", 0))?;
/// assert_eq!(env.name(), "demo_plate");
/// # Ok::<(), hil_core::HilError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoPlateConfig {
    /// Foods on the plate, in order (names from the feeding data, see
    /// [`DemoPlate::foods`]).
    pub foods: Vec<String>,
    /// How many times the list is served (default 1); foods × repeat is at
    /// most [`limits::ITEMS_PER_EPISODE`].
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

    fn validate(&self) -> Result<()> {
        DemoPlate::check(&self.foods, self.repeat).map(drop)
    }
}

/// A plate of foods with published per-action success rates. Contexts are
/// the one-hot code of the food followed by two noise features, so every
/// attempt observes a fresh context; outcomes are seeded Bernoulli draws.
///
/// ```
/// use hil_core::Environment;
/// use hil_envs::demo_plate::DemoPlate;
///
/// let mut plate = DemoPlate::new(&["banana".into(), "carrot".into()], 1)?;
/// plate.reset(7)?;
/// let item = plate.next_item()?.unwrap();
/// assert_eq!(item.description.as_deref(), Some("a round slice of banana"));
/// plate.observe()?;
/// assert_eq!(plate.best_action().map(|a| a.0), Some(4)); // TA0
/// assert!(DemoPlate::new(&["pizza".into()], 1).is_err());
/// # Ok::<(), hil_core::HilError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DemoPlate {
    task: &'static FeedingTask,
    /// Foods on the plate (indices into the task's foods), first-seen order:
    /// the one-hot part of the context.
    types: Vec<usize>,
    /// The episode's items, as indices into the task's foods.
    order: Vec<usize>,
    rng: ChaCha8Rng,
    next: usize,
    current: Option<(Item, usize)>,
    calls: CallOrder,
}

impl DemoPlate {
    /// The foods a demo plate can hold: every food of the feeding data.
    pub fn foods() -> Vec<&'static str> {
        FeedingTask::bundled().food_names()
    }

    /// A plate serving `foods` (names from [`DemoPlate::foods`]) `repeat`
    /// times: at most [`limits::ITEMS_PER_EPISODE`] items in all.
    pub fn new(foods: &[String], repeat: usize) -> Result<Self> {
        let task = FeedingTask::bundled();
        let once = Self::check(foods, repeat)?;
        let mut types = Vec::new();
        for &idx in &once {
            if !types.contains(&idx) {
                types.push(idx);
            }
        }
        let order = once.repeat(repeat);
        Ok(Self {
            task,
            types,
            order,
            rng: ChaCha8Rng::seed_from_u64(0),
            next: 0,
            current: None,
            calls: CallOrder::new("demo_plate"),
        })
    }

    /// Checks a plate against the limits before anything proportional to
    /// `repeat` is allocated; returns the foods' indices, once through.
    fn check(foods: &[String], repeat: usize) -> Result<Vec<usize>> {
        if foods.is_empty() {
            return Err(HilError::invalid_parameter(
                "foods",
                "[]",
                "the plate needs at least one food",
            ));
        }
        limits::check_count("foods", foods.len(), limits::ITEMS_PER_EPISODE)?;
        // The plate serves foods × repeat items.
        let max_repeat = limits::ITEMS_PER_EPISODE / foods.len() as u64;
        limits::check_count("repeat", repeat, max_repeat)?;
        let task = FeedingTask::bundled();
        foods
            .iter()
            .map(|f| {
                task.foods.iter().position(|k| &k.name == f).ok_or_else(|| {
                    HilError::invalid_parameter(
                        "foods",
                        f,
                        format!("unknown food; choose from {:?}", Self::foods()),
                    )
                })
            })
            .collect()
    }

    fn food(&self) -> Result<&'static FoodFacts> {
        let task = self.task;
        self.current
            .as_ref()
            .map(|(_, f)| &task.foods[*f])
            .ok_or_else(|| HilError::state("demo_plate", "no current item: call next_item first"))
    }

    fn rates(&self) -> Result<&'static [f64]> {
        let food = self.food()?;
        food.rates_in(ALL_SETTINGS).ok_or_else(|| {
            HilError::state("demo_plate", format!("no pooled rates for `{}`", food.name))
        })
    }
}

impl Environment for DemoPlate {
    fn name(&self) -> &str {
        "demo_plate"
    }
    fn action_space(&self) -> &ActionSpace {
        self.task.action_space()
    }
    fn context_dim(&self) -> usize {
        self.types.len() + 2
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.current = None;
        self.calls.on_reset();
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        let Some(&food) = self.order.get(self.next) else {
            self.current = None;
            self.calls.on_next_item(false);
            return Ok(None);
        };
        let facts = &self.task.foods[food];
        let item =
            Item::new(self.next, facts.name.clone()).with_description(facts.description.clone());
        self.next += 1;
        self.current = Some((item.clone(), food));
        self.calls.on_next_item(true);
        Ok(Some(item))
    }
    fn observe(&mut self) -> Result<Context> {
        self.calls.on_observe()?;
        let food = self.current.as_ref().map(|(_, f)| *f).ok_or_else(|| {
            HilError::state("demo_plate", "no current item: call next_item first")
        })?;
        let mut x: Vec<f64> = self.types.iter().map(|t| f64::from(*t == food)).collect();
        x.push(self.rng.random_range(-0.1..0.1));
        x.push(self.rng.random_range(-0.1..0.1));
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.task.action_space().check(arm)?;
        self.calls.on_execute()?;
        let p = self.rates()?[arm.0];
        Ok(Outcome::new(self.rng.random_bool(p)).with_success_probability(p))
    }
    fn best_action(&self) -> Option<ArmId> {
        self.food().ok().map(FoodFacts::best_action)
    }
    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref().map(|(i, _)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_conformance::check_environment;

    #[test]
    fn the_demo_plate_conforms() {
        check_environment(
            &|| {
                Ok(Box::new(DemoPlate::new(
                    &["banana".into(), "carrot".into(), "grape".into()],
                    2,
                )?))
            },
            4,
        )
        .unwrap();
    }

    #[test]
    fn bad_plates_are_invalid_parameters() {
        for (foods, repeat) in [
            (vec!["pizza".to_string()], 1),
            (vec![], 1),
            (vec!["kiwi".into()], 0),
        ] {
            assert!(matches!(
                DemoPlate::new(&foods, repeat),
                Err(HilError::InvalidParameter { .. })
            ));
        }
    }

    #[test]
    fn out_of_order_calls_are_state_errors() {
        let mut p = DemoPlate::new(&["apple".into()], 1).unwrap();
        assert!(matches!(p.observe(), Err(HilError::State { .. })));
        p.reset(1).unwrap();
        p.next_item().unwrap();
        assert!(matches!(p.execute(ArmId(0)), Err(HilError::State { .. })));
        p.observe().unwrap();
        p.execute(ArmId(0)).unwrap();
        assert!(p.next_item().unwrap().is_none());
        assert!(matches!(p.observe(), Err(HilError::State { .. })));
    }

    #[test]
    fn items_use_the_feeding_descriptions_and_rates() {
        let mut p = DemoPlate::new(&["grape".into()], 2).unwrap();
        p.reset(3).unwrap();
        let mut n = 0;
        while let Some(item) = p.next_item().unwrap() {
            assert_eq!(item.description.as_deref(), Some("a grape"));
            p.observe().unwrap();
            let out = p.execute(ArmId(3)).unwrap();
            assert_eq!(out.success_probability, Some(0.87));
            n += 1;
        }
        assert_eq!(n, 2);
    }
}
