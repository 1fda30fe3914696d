//! Running built components over several episodes: [`Experiment`] and
//! its [`ExperimentSummary`]. `hil_experiments::ExperimentConfig::build`
//! makes one from a config file.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use hil_core::metrics::EpisodeMetrics;
use hil_core::session::{EpisodeReport, Session, SessionObserver, SessionSettings, splitmix};
use hil_core::{Environment, Policy, QueryChannel, Result, WorkloadModel};
use hil_stats::mean_std;

/// The built components of an experiment, ready to run.
pub struct Experiment {
    /// Loop settings.
    pub settings: SessionSettings,
    /// Master seed.
    pub seed: u64,
    /// Number of episodes.
    pub episodes: usize,
    /// The environment.
    pub environment: Box<dyn Environment>,
    /// The policy (keeps learning across episodes).
    pub policy: Box<dyn Policy>,
    /// The query channel.
    pub channel: Box<dyn QueryChannel>,
    /// The workload model that evolves and scores workload.
    pub workload: Arc<dyn WorkloadModel>,
    /// The model the policy forecasts with, if different.
    pub forecast: Option<Arc<dyn WorkloadModel>>,
}

impl std::fmt::Debug for Experiment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Experiment")
            .field("settings", &self.settings)
            .field("seed", &self.seed)
            .field("episodes", &self.episodes)
            .field("environment", &self.environment.name())
            .field("policy", &self.policy.name())
            .field("channel", &self.channel.name())
            .field("workload", &self.workload.name())
            .finish()
    }
}

/// Summary of an experiment's episodes.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExperimentSummary {
    /// Per-episode metrics, in order.
    pub episodes: Vec<EpisodeMetrics>,
    /// Mean and std over episodes of r_task_avg.
    pub r_task_avg: (f64, f64),
    /// Mean and std over episodes of ΔWL.
    pub delta_wl: (f64, f64),
    /// Mean and std over episodes of f_q.
    pub f_q: (f64, f64),
    /// Mean and std over episodes of t_conv.
    pub t_conv: (f64, f64),
}

impl ExperimentSummary {
    /// Summarises episode metrics.
    pub fn new(episodes: Vec<EpisodeMetrics>) -> Self {
        let col =
            |f: fn(&EpisodeMetrics) -> f64| mean_std(&episodes.iter().map(f).collect::<Vec<_>>());
        Self {
            r_task_avg: col(|m| m.r_task_avg),
            delta_wl: col(|m| m.delta_wl),
            f_q: col(|m| m.f_q),
            t_conv: col(|m| m.t_conv),
            episodes,
        }
    }
}

impl Experiment {
    /// The seed of episode `k`.
    pub fn episode_seed(&self, k: usize) -> u64 {
        splitmix(self.seed, 1000 + k as u64)
    }

    /// Runs every episode, calling `on_episode` after each.
    pub fn run(
        &mut self,
        observers: &mut [&mut dyn SessionObserver],
        mut on_episode: impl FnMut(usize, &EpisodeReport),
    ) -> Result<ExperimentSummary> {
        // An experiment built in code (hil-py's run_session) skips the
        // config's checks: repeat them before the work they bound.
        hil_config::limits::check_count("episodes", self.episodes, hil_config::limits::EPISODES)?;
        self.settings.validate()?;
        hil_config::check_session_limits(&self.settings)?;
        let mut metrics = Vec::with_capacity(self.episodes);
        for k in 0..self.episodes {
            let seed = self.episode_seed(k);
            let mut session = Session::new(
                self.settings.clone(),
                self.environment.as_mut(),
                self.policy.as_mut(),
                self.channel.as_mut(),
                self.workload.clone(),
            )
            .with_forecast(self.forecast.clone());
            let report = session.run_episode(seed, observers)?;
            on_episode(k, &report);
            metrics.push(report.metrics);
        }
        Ok(ExperimentSummary::new(metrics))
    }
}
