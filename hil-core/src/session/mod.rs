//! The session loop: one place where environment, policy, channel and
//! workload model meet, with the paper's semantics.
//!
//! - An episode is a sequence of items; every attempt at an item is one
//!   timestep and observes a fresh context of the item.
//! - The policy decides to act or to query. After a query for the current
//!   item, the expert's action is executed again on every later attempt at
//!   that item (the policy is not consulted, but observes every outcome).
//! - An item ends on success or after `n_att` attempts.
//! - Workload is the paper's WL_t = f(WL_0, Q_t), evaluated at every step
//!   with the session's workload model; the episode is scored at its last
//!   step (WL_T, [`EpisodeMetrics`]).
//! - What components return is checked as it arrives: a policy's
//!   diagnostics must be finite, every workload prediction in [0, 1], a
//!   response time finite and not negative, a success probability in
//!   [0, 1]. The error names the component and the field.
//! - An outside loop may drive an episode one decision at a time
//!   ([`step`]: `next_decision` asks, `feed_decision` tells);
//!   [`Session::run_episode`] is a loop over [`Session::step`].

mod checks;
pub mod observer;
pub mod step;

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::action::ArmId;
use crate::channel::QueryChannel;
use crate::environment::Environment;
use crate::error::{HilError, Result};
use crate::metrics::EpisodeMetrics;
use crate::policy::Policy;
use crate::workload::{DEFAULT_WL0, WorkloadModel, check_wl0};

pub use crate::event::{self, PendingStep, StepDecision, StepEvent};
pub use observer::{EventCollector, SessionObserver};
pub use step::Episode;

/// The paper's attempt limit per item in simulation.
pub const DEFAULT_N_ATT: u32 = 10;

/// Settings of the session loop.
///
/// ```
/// let s = hil_core::SessionSettings::default();
/// assert_eq!((s.n_att, s.wl0), (10, 0.5));
/// s.validate().unwrap();
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[non_exhaustive]
pub struct SessionSettings {
    /// Maximum attempts per item (N_att).
    pub n_att: u32,
    /// Initial workload WL_0 in [0, 1].
    pub wl0: f64,
    /// Stop after this many items even if the environment has more.
    pub max_items: Option<usize>,
}

impl Default for SessionSettings {
    fn default() -> Self {
        Self {
            n_att: DEFAULT_N_ATT,
            wl0: DEFAULT_WL0,
            max_items: None,
        }
    }
}

impl SessionSettings {
    /// The defaults with at most `n_att` attempts per item.
    pub fn with_n_att(mut self, n_att: u32) -> Self {
        self.n_att = n_att;
        self
    }

    /// With initial workload `wl0`.
    pub fn with_wl0(mut self, wl0: f64) -> Self {
        self.wl0 = wl0;
        self
    }

    /// Stopping after `max_items` items (or when the environment runs out).
    pub fn with_max_items(mut self, max_items: Option<usize>) -> Self {
        self.max_items = max_items;
        self
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        if self.n_att == 0 {
            return Err(HilError::invalid_parameter(
                "n_att",
                0,
                "must be at least 1",
            ));
        }
        check_wl0(self.wl0)
    }
}

/// Independent seeds for each component, derived from one session seed so
/// that adding randomness to one component never shifts another's stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ComponentSeeds {
    /// Seed for the environment's `reset`.
    pub environment: u64,
    /// Seed for the policy.
    pub policy: u64,
    /// Seed for the query channel.
    pub channel: u64,
}

impl ComponentSeeds {
    /// Derives the component seeds from `seed` (SplitMix64 streams). This is
    /// what [`Session::run_episode`] does; a protocol that crosses
    /// environment seeds with policy seeds sets them explicitly and calls
    /// [`Session::run_episode_with_seeds`].
    pub fn derive(seed: u64) -> Self {
        Self {
            environment: splitmix(seed, 1),
            policy: splitmix(seed, 2),
            channel: splitmix(seed, 3),
        }
    }
}

/// SplitMix64 of `seed` on stream `stream`: a cheap, well-mixed derivation.
pub fn splitmix(seed: u64, stream: u64) -> u64 {
    let mut z = seed
        .wrapping_add(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Everything one episode produced.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EpisodeReport {
    /// The session seed.
    pub seed: u64,
    /// Every step, in order.
    pub events: Vec<StepEvent>,
    /// The metrics computed from the events.
    pub metrics: EpisodeMetrics,
}

/// The components of a session, borrowed so that the caller keeps them
/// (a policy carries its learning on to the next episode).
///
/// ```
/// use std::sync::Arc;
/// use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
/// use hil_core::{ActionSpace, ArmId, Choice, Environment, PerfectExpert, Session, SessionSettings};
///
/// let actions = ActionSpace::new(["left", "right"]).unwrap();
/// let items = vec![("apple", vec![0.9, 0.1]), ("pear", vec![0.2, 0.8])];
/// let mut env = TableEnv::new(actions, items).unwrap();
/// let dim = env.context_dim();
/// let mut policy = ScriptedPolicy::new(2, dim, vec![Choice::Act { arm: ArmId(0) }]);
/// let mut expert = PerfectExpert::default();
/// let mut session = Session::new(
///     SessionSettings::default().with_n_att(2),
///     &mut env,
///     &mut policy,
///     &mut expert,
///     Arc::new(CountingWorkload::new(0.1)),
/// );
/// let report = session.run_episode(7, &mut []).unwrap();
/// assert_eq!(report.metrics.n_items, 2);
/// assert_eq!(report.metrics.n_q, 0); // this script never asks
/// ```
#[non_exhaustive]
pub struct Session<'a> {
    /// Loop settings.
    pub settings: SessionSettings,
    /// Where the robot acts.
    pub environment: &'a mut dyn Environment,
    /// Who decides.
    pub policy: &'a mut dyn Policy,
    /// How queries reach the expert.
    pub channel: &'a mut dyn QueryChannel,
    /// The workload model that evolves the person's workload state and scores
    /// the episode (in simulation, it stands in for the person).
    pub workload: Arc<dyn WorkloadModel>,
    /// The workload model the policy forecasts with; `None` means the same as
    /// `workload`. They differ in the paper's cross-data experiment.
    pub forecast: Option<Arc<dyn WorkloadModel>>,
}

impl<'a> Session<'a> {
    /// A session of `policy` in `environment`, asking through `channel`,
    /// whose workload evolves (and is forecast) by `workload`.
    pub fn new(
        settings: SessionSettings,
        environment: &'a mut dyn Environment,
        policy: &'a mut dyn Policy,
        channel: &'a mut dyn QueryChannel,
        workload: Arc<dyn WorkloadModel>,
    ) -> Self {
        Self {
            settings,
            environment,
            policy,
            channel,
            workload,
            forecast: None,
        }
    }

    /// With a different model for the policy's forecasts (the paper's
    /// cross-data experiment); `None` forecasts with the session's model.
    pub fn with_forecast(mut self, forecast: Option<Arc<dyn WorkloadModel>>) -> Self {
        self.forecast = forecast;
        self
    }
}

impl std::fmt::Debug for Session<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("settings", &self.settings)
            .field("environment", &self.environment.name())
            .field("policy", &self.policy.name())
            .field("channel", &self.channel.name())
            .field("workload", &self.workload.name())
            .field(
                "forecast",
                &self.forecast.as_ref().map(|m| m.name().to_string()),
            )
            .finish()
    }
}

impl Session<'_> {
    /// Runs one episode seeded by `seed` (each component's seed derived from
    /// it, [`ComponentSeeds::derive`]), reporting to `observers`.
    pub fn run_episode(
        &mut self,
        seed: u64,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<EpisodeReport> {
        self.run_episode_with_seeds(seed, ComponentSeeds::derive(seed), observers)
    }

    /// Runs one episode with explicit per-component seeds; `seed` labels
    /// the episode in its report and for observers. It starts the episode,
    /// takes [`Session::step`] until no item is left and finishes it.
    pub fn run_episode_with_seeds(
        &mut self,
        seed: u64,
        seeds: ComponentSeeds,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<EpisodeReport> {
        let mut episode = self.start_episode_with_seeds(seed, seeds, observers)?;
        while self.step(&mut episode, observers)? {}
        self.finish_episode(&mut episode, observers)
    }

    fn check_arm(&self, arm: ArmId, what: &str) -> Result<()> {
        self.environment
            .action_space()
            .check(arm)
            .map_err(|e| HilError::invalid_input(what.to_string(), e.to_string()))
    }

    fn check_shapes(&self) -> Result<()> {
        let (env_arms, env_dim) = (
            self.environment.action_space().len(),
            self.environment.context_dim(),
        );
        if self.policy.n_arms() != env_arms || self.policy.dim() != env_dim {
            return Err(HilError::invalid_input(
                format!("policy `{}`", self.policy.name()),
                format!(
                    "it is built for {} arms and d = {}, but environment `{}` has {} arms and d = {}",
                    self.policy.n_arms(),
                    self.policy.dim(),
                    self.environment.name(),
                    env_arms,
                    env_dim
                ),
            ));
        }
        Ok(())
    }
}
