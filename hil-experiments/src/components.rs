//! The simulated-testbed protocol's pluggable parts: what answers queries
//! ([`ChannelFactory`]) and what presents the food items
//! ([`EnvironmentFactory`]) in every episode. The paper's are the defaults
//! ([`PerfectExpertChannel`], [`DatasetReplay`]); the settings may name any
//! registered or plugin type instead ([`ConfiguredChannel`],
//! [`ConfiguredEnvironment`]), and a program may inject its own factory
//! ([`Protocol::with_channel`](crate::Protocol::with_channel),
//! [`Protocol::with_environment`](crate::Protocol::with_environment)).
//!
//! Whatever the factory, every method meets the same episodes: the protocol
//! builds a fresh environment and channel per episode and seeds them from
//! the run's key alone, so common random numbers hold as long as the
//! factory's components are deterministic given their seeds.
//!
//! ```toml
//! # in a protocol settings file
//! channel = { type = "simulated_expert", p_correct = 0.8 }
//! environment = { type = "food_replay", outcomes = "sample" }
//! ```

use std::path::Path;
use std::sync::Arc;

use hil_config::{BuildContext, EnvironmentConfig, QueryChannelConfig, TaskContext};
use hil_core::{Environment, HilError, QueryChannel, Result};
use hil_envs::{DatasetReplayEnv, FoodDataset};

use crate::testbed::Phase;

/// What an episode's environment is built for.
#[derive(Clone, Copy, Debug)]
pub struct EpisodeSpec<'a> {
    /// The protocol's dataset.
    pub dataset: &'a Arc<FoodDataset>,
    /// The dataset's directory, if the settings name one (none: the
    /// bundled dataset).
    pub dataset_path: Option<&'a Path>,
    /// Validation or test.
    pub phase: Phase,
    /// The phase's foods (the split's validation or test foods).
    pub foods: &'a [String],
    /// Items per episode.
    pub items_per_episode: usize,
    /// The episode's environment seed (the session resets the environment
    /// with it as well): equal for every method at one seed index.
    pub seed: u64,
}

/// Builds the environment of every episode.
pub trait EnvironmentFactory: Send + Sync {
    /// What errors and debug output call it.
    fn name(&self) -> String {
        "custom environment factory".into()
    }

    /// A fresh environment for one episode. Its actions and context
    /// dimension must be the dataset's (the policies are built for them);
    /// the protocol checks that.
    fn build(&self, spec: &EpisodeSpec<'_>) -> Result<Box<dyn Environment>>;
}

impl<F> EnvironmentFactory for F
where
    F: Fn(&EpisodeSpec<'_>) -> Result<Box<dyn Environment>> + Send + Sync,
{
    fn build(&self, spec: &EpisodeSpec<'_>) -> Result<Box<dyn Environment>> {
        self(spec)
    }
}

/// Builds the query channel of every episode.
pub trait ChannelFactory: Send + Sync {
    /// What errors and debug output call it.
    fn name(&self) -> String {
        "custom channel factory".into()
    }

    /// A fresh channel for one episode, for the task `ctx` describes (the
    /// dataset's actions and dimension).
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>>;
}

impl<F> ChannelFactory for F
where
    F: Fn(&TaskContext) -> Result<Box<dyn QueryChannel>> + Send + Sync,
{
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        self(ctx)
    }
}

/// The paper's environment: [`DatasetReplayEnv`] over the phase's foods.
#[derive(Clone, Copy, Debug, Default)]
pub struct DatasetReplay;

impl EnvironmentFactory for DatasetReplay {
    fn name(&self) -> String {
        "dataset replay (the paper's)".into()
    }

    fn build(&self, spec: &EpisodeSpec<'_>) -> Result<Box<dyn Environment>> {
        Ok(Box::new(DatasetReplayEnv::new(
            spec.dataset.clone(),
            spec.foods,
            spec.items_per_episode,
        )?))
    }
}

/// The paper's simulated expert: a perfect expert answering with the best
/// action.
#[derive(Clone, Copy, Debug, Default)]
pub struct PerfectExpertChannel;

impl ChannelFactory for PerfectExpertChannel {
    fn name(&self) -> String {
        "perfect expert (the paper's)".into()
    }

    fn build(&self, _ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        Ok(Box::new(hil_core::PerfectExpert::default()))
    }
}

/// A channel of any registered [`QueryChannelConfig`] type (built-in,
/// plugin or registered from Python), from its table in the settings.
#[derive(Clone, Debug)]
pub struct ConfiguredChannel {
    table: toml::Table,
}

impl ConfiguredChannel {
    /// The channel `table` describes (`type = "..."` and its parameters),
    /// checked to parse and validate.
    pub fn new(table: toml::Table) -> Result<Self> {
        let c = Self { table };
        c.config()?.validate().map_err(|e| c.invalid(e))?;
        Ok(c)
    }

    fn config(&self) -> Result<Box<dyn QueryChannelConfig>> {
        hil_plugin::component::<_, dyn QueryChannelConfig>(toml::Value::Table(self.table.clone()))
            .map_err(|e: toml::de::Error| self.invalid(e.message().trim()))
    }

    fn invalid(&self, why: impl std::fmt::Display) -> HilError {
        HilError::invalid_parameter("channel", type_of(&self.table), why.to_string())
    }
}

impl ChannelFactory for ConfiguredChannel {
    fn name(&self) -> String {
        format!("channel `{}`", type_of(&self.table))
    }

    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        self.config()?.build(ctx)
    }
}

/// An environment of any registered [`EnvironmentConfig`] type (built-in,
/// plugin or registered from Python), from its table in the settings. The
/// protocol sets three of its parameters per episode: `foods` (the phase's
/// foods), `items_per_episode`, and `dataset` (the settings' dataset
/// directory, when they name one); the table must not set them itself. The
/// built-in `food_replay` type takes exactly these, so `environment = {
/// type = "food_replay" }` runs the paper's environment through this path.
#[derive(Clone, Debug)]
pub struct ConfiguredEnvironment {
    table: toml::Table,
}

/// The parameters [`ConfiguredEnvironment`] sets.
pub const PROTOCOL_ENVIRONMENT_PARAMETERS: [&str; 3] = ["foods", "items_per_episode", "dataset"];

impl ConfiguredEnvironment {
    /// The environment `table` describes; fails if it sets a parameter the
    /// protocol sets ([`PROTOCOL_ENVIRONMENT_PARAMETERS`]).
    pub fn new(table: toml::Table) -> Result<Self> {
        if let Some(k) = PROTOCOL_ENVIRONMENT_PARAMETERS
            .iter()
            .find(|k| table.contains_key(**k))
        {
            return Err(HilError::invalid_parameter(
                format!("environment.{k}"),
                &table[*k],
                "the protocol sets it for every episode (the phase's foods, the settings' \
                 items_per_episode and dataset); remove it",
            ));
        }
        Ok(Self { table })
    }

    /// The config of an episode over `foods` with `items_per_episode`
    /// items (from the dataset at `dataset_path`, if given), validated.
    pub fn config(
        &self,
        foods: &[String],
        items_per_episode: usize,
        dataset_path: Option<&Path>,
    ) -> Result<Box<dyn EnvironmentConfig>> {
        let mut t = self.table.clone();
        t.insert(
            "foods".into(),
            toml::Value::Array(
                foods
                    .iter()
                    .map(|f| toml::Value::String(f.clone()))
                    .collect(),
            ),
        );
        t.insert(
            "items_per_episode".into(),
            toml::Value::Integer(i64::try_from(items_per_episode).unwrap_or(i64::MAX)),
        );
        if let Some(p) = dataset_path {
            t.insert(
                "dataset".into(),
                toml::Value::String(p.to_string_lossy().into_owned()),
            );
        }
        let invalid =
            |why: String| HilError::invalid_parameter("environment", type_of(&self.table), why);
        let config = hil_plugin::component::<_, dyn EnvironmentConfig>(toml::Value::Table(t))
            .map_err(|e: toml::de::Error| invalid(e.message().trim().to_string()))?;
        config.validate().map_err(|e| invalid(e.to_string()))?;
        Ok(config)
    }
}

impl EnvironmentFactory for ConfiguredEnvironment {
    fn name(&self) -> String {
        format!("environment `{}`", type_of(&self.table))
    }

    fn build(&self, spec: &EpisodeSpec<'_>) -> Result<Box<dyn Environment>> {
        self.config(spec.foods, spec.items_per_episode, spec.dataset_path)?
            .build(&BuildContext::new(".", spec.seed))
    }
}

/// The `type` a component table names (for messages).
fn type_of(table: &toml::Table) -> String {
    table
        .get("type")
        .and_then(|t| t.as_str())
        .unwrap_or("<no type>")
        .to_string()
}

/// Checks that an episode's environment acts among the dataset's actions on
/// contexts of its dimension, as the protocol's policies were built for.
pub fn check_matches_task(env: &dyn Environment, ctx: &TaskContext, factory: &str) -> Result<()> {
    if env.action_space() != ctx.action_space() {
        return Err(HilError::invalid_parameter(
            "environment",
            factory,
            format!(
                "its actions [{}] are not the dataset's [{}]",
                env.action_space().names().join(", "),
                ctx.action_space().names().join(", ")
            ),
        ));
    }
    if env.context_dim() != ctx.context_dim() {
        return Err(HilError::invalid_parameter(
            "environment",
            factory,
            format!(
                "its context dimension {} is not the dataset's {}",
                env.context_dim(),
                ctx.context_dim()
            ),
        ));
    }
    Ok(())
}

/// A factory as shared by the protocol.
pub type SharedEnvironmentFactory = Arc<dyn EnvironmentFactory>;
/// A factory as shared by the protocol.
pub type SharedChannelFactory = Arc<dyn ChannelFactory>;
