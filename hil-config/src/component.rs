//! The four component-config traits: serialisable recipes that typetag
//! names in configs (`type = "..."`).

use std::sync::Arc;

use hil_core::{Environment, LabelledObservation, Policy, QueryChannel, Result, WorkloadModel};

use crate::{BuildContext, TaskContext};

/// A serialisable recipe for a [`Policy`].
#[typetag::serde(tag = "type")]
pub trait PolicyConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the policy for the environment
    /// described by `ctx`.
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn Policy>>;

    /// Checks the parameters that need no environment. A config loader
    /// (`hil_experiments::ExperimentConfig::parse`) calls it on every
    /// component it reads and turns an error into a
    /// [`ConfigError`](hil_core::ConfigError) naming the file, line and
    /// field ([`error_in_section`](crate::error_in_section)); `build` must check them too
    /// (calling this is the simplest way). It must be cheap: no I/O and
    /// nothing allocated in proportion to a count (check counts against
    /// [`limits`](crate::limits)). The default accepts everything.
    fn validate(&self) -> Result<()> {
        Ok(())
    }

    /// Whether the policy's decisions read the workload forecast. A protocol
    /// runs a policy that does not once and scores it under every workload
    /// model; one that does runs once per deciding model. The default
    /// (`true`) is the safe assumption for a policy nobody described.
    fn uses_workload_forecast(&self) -> bool {
        true
    }

    /// Whether the policy's decisions depend on its own seed
    /// ([`Policy::seed`]). A protocol runs a stochastic policy under several
    /// policy seeds. The default (`true`) is the safe assumption.
    fn is_stochastic(&self) -> bool {
        true
    }
}

/// A serialisable recipe for an [`Environment`].
#[typetag::serde(tag = "type")]
pub trait EnvironmentConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the environment.
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Environment>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }

    /// Offline data for pretraining policies (e.g. the pretraining foods of
    /// a dataset), handed to policy configs through
    /// [`TaskContext::pretraining`]. None by default.
    fn pretraining(&self, ctx: &BuildContext) -> Result<Option<Arc<[LabelledObservation]>>> {
        let _ = ctx;
        Ok(None)
    }

    /// For an environment calibrated to a published table: every item of
    /// an episode, in order, with the action an expert names for it and
    /// that action's published success rate where the environment places
    /// the item. A study reads from it what an always-asking robot can
    /// score if every attempt succeeds at the published rate
    /// (`hil_experiments::user_study::PublishedReference`). None (the
    /// default) for an environment without one.
    fn published_expert_rates(&self) -> Result<Option<Vec<ExpertRate>>> {
        Ok(None)
    }
}

/// One item's expert action and its published success rate
/// ([`EnvironmentConfig::published_expert_rates`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ExpertRate {
    /// The item's label (`banana`).
    pub item: String,
    /// The action an expert names for it (`TA0`).
    pub action: String,
    /// That action's published success rate per attempt, in [0, 1], where
    /// the environment places the item (the mean over its settings when it
    /// draws one at random).
    pub rate: f64,
}

/// A serialisable recipe for a [`WorkloadModel`].
#[typetag::serde(tag = "type")]
pub trait WorkloadModelConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds (or loads) the model.
    fn build(&self, ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

/// A serialisable recipe for a [`QueryChannel`].
#[typetag::serde(tag = "type")]
pub trait QueryChannelConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the channel.
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

impl BuildContext {
    /// The context for the policy and channel of a built environment: its
    /// action space, its context dimension and the pretraining data its
    /// `config` offers. Every protocol that builds an environment and then
    /// the components around it goes through this, so they all see the same
    /// facts.
    pub fn describe_environment(
        &self,
        config: &dyn EnvironmentConfig,
        environment: &dyn Environment,
    ) -> Result<TaskContext> {
        let task = TaskContext::new(
            self.clone(),
            environment.action_space().clone(),
            environment.context_dim(),
        );
        Ok(match config.pretraining(self)? {
            Some(data) => task.with_pretraining(data),
            None => task,
        })
    }
}
