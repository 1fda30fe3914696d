//! The records of an interaction log, one JSON object per line.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use hil_core::decision::Outcome;
use hil_core::metrics::EpisodeMetrics;
use hil_core::session::PendingStep;
use hil_core::time::Timestep;

/// The `format` field of every log header.
pub const FORMAT_NAME: &str = "hil-interaction-record";
/// The version of the format this crate writes and reads.
///
/// - 3: every line starts with a `chain` digest ([`super::chain`]) and the
///   header carries `config_digest`, the SHA-256 of its `config`;
/// - 2: a step's workload is `wl_t`, the paper's WL_t = f(WL_0, Q_t) at every
///   step, and episode metrics score WL_T at the last step (with `t_final`,
///   `queries` and `scoring_model`);
/// - 1: a step's `wl` was the workload tracked at query steps only.
pub const FORMAT_VERSION: u32 = 3;

/// The first line of a log: everything needed to rebuild the session.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Always [`FORMAT_NAME`].
    pub format: String,
    /// Always [`FORMAT_VERSION`] for logs this crate writes.
    pub version: u32,
    /// The experiment's master seed (also in `config`; kept here for readers).
    pub seed: u64,
    /// Number of episodes the session runs.
    pub episodes: usize,
    /// Where the config was read from (for messages only).
    pub config_path: PathBuf,
    /// Directory relative paths in the config resolve against.
    pub base_dir: PathBuf,
    /// The experiment config, verbatim (TOML).
    pub config: String,
    /// SHA-256 of `config` (lower-case hex): checked when the log is read,
    /// so the config a session resumes with is the one it started with.
    pub config_digest: String,
    /// For a keyed log ([`super::key`]), the id of its key (never the key
    /// itself), so a reader knows a key is needed and which; absent (not
    /// written at all) in an unkeyed log. Part of the header's chained
    /// content, so it cannot be changed without breaking the chain.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record_key: Option<String>,
}

impl Header {
    /// A header for a session of `config` (TOML text read from `config_path`).
    pub fn new(
        config: &str,
        config_path: impl Into<PathBuf>,
        base_dir: impl Into<PathBuf>,
        seed: u64,
        episodes: usize,
    ) -> Self {
        Self {
            format: FORMAT_NAME.into(),
            version: FORMAT_VERSION,
            seed,
            episodes,
            config_path: config_path.into(),
            base_dir: base_dir.into(),
            config: config.into(),
            config_digest: super::chain::digest_hex(config),
            record_key: None,
        }
    }
}

/// One line of an interaction log.
///
/// A session writes, in order: a `header`; per episode an `episode_start`,
/// per step a `step` (fsync'ed before the robot acts) and its `outcome`,
/// then `episode_end` and, if the policy can save its state, a
/// `checkpoint`. A resumed session adds a `resumed` line where it picked up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "record", rename_all = "snake_case")]
pub enum Record {
    /// The first line.
    Header(Header),
    /// An episode starts.
    EpisodeStart {
        /// Episode number (0-based).
        episode: usize,
        /// The episode's seed.
        seed: u64,
    },
    /// A step is decided (decision, diagnostics, query kind, response, the
    /// arm to execute and WL_t). Written and fsync'ed before the robot acts.
    Step {
        /// Episode number.
        episode: usize,
        /// The step.
        step: PendingStep,
    },
    /// The outcome of the step at `t`.
    Outcome {
        /// Episode number.
        episode: usize,
        /// The step's timestep.
        t: Timestep,
        /// What happened.
        outcome: Outcome,
    },
    /// An episode ended.
    EpisodeEnd {
        /// Episode number.
        episode: usize,
        /// Its metrics.
        metrics: EpisodeMetrics,
    },
    /// The policy's state after episode `episode` ([`hil_core::Policy::save`]).
    Checkpoint {
        /// Episode number.
        episode: usize,
        /// The saved state.
        policy: Value,
    },
    /// A session was resumed from this log.
    Resumed {
        /// Number of valid lines found (including the header).
        lines: usize,
        /// Bytes of an incomplete last line that were discarded.
        truncated_bytes: u64,
        /// The episode the policy was restored at (a checkpoint), if any.
        from_checkpoint: Option<usize>,
    },
}

impl Record {
    /// The record's kind, as written in its `record` field.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Header(_) => "header",
            Self::EpisodeStart { .. } => "episode_start",
            Self::Step { .. } => "step",
            Self::Outcome { .. } => "outcome",
            Self::EpisodeEnd { .. } => "episode_end",
            Self::Checkpoint { .. } => "checkpoint",
            Self::Resumed { .. } => "resumed",
        }
    }
}
