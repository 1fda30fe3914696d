//! The interaction record: every step of a session in a JSONL log that
//! survives a crash, and resuming a session from it.
//!
//! # Format
//!
//! One JSON object per line, tagged by its `record` field (see [`Record`]).
//! Every line starts with a `chain` field, the SHA-256 of the previous
//! line's `chain` and the line's own content ([`chain`]), which makes the
//! log tamper-evident.
//!
//! | record | when | fields |
//! |---|---|---|
//! | `header` | first line | `format` (`hil-interaction-record`), `version` (3), `seed`, `episodes`, `config_path`, `base_dir`, `config` (the experiment TOML, verbatim), `config_digest` (its SHA-256) |
//! | `episode_start` | episode begins | `episode`, `seed` |
//! | `step` | decided, **fsync'ed before the robot acts** | `episode`, `step`: `t`, `item_index`, `item_label`, `attempt`, `context`, `decision` (`act` / `query` with its `kind` = response type, difficulty, distraction, and `fallback` / `follow_expert`), `diagnostics`, `response` (answer, expert arm, response time; a `timed_out` answer means the policy acted on its own), `arm`, `wl_t` (WL_t = f(WL_0, Q_t) at this step) |
//! | `outcome` | after execution, fsync'ed | `episode`, `t`, `outcome` (`success`, `success_probability`) |
//! | `episode_end` | episode ends | `episode`, `metrics` |
//! | `checkpoint` | after `episode_end`, if the policy can save its state | `episode`, `policy` (its [`crate::Policy::save`]) |
//! | `resumed` | where a resumed session started appending | `lines`, `truncated_bytes`, `from_checkpoint` |
//!
//! # One writer, and tamper evidence
//!
//! A [`RecordLog`] holds an exclusive lock on its file for as long as it
//! lives ([`lock`]): a second writer, such as a second `hil run --resume` or
//! a resume while the original run still writes, is refused with an error
//! naming the process, host and start time of the holder.
//!
//! [`RecordLog::open`] reads at most [`crate::files::limits::LOG`] bytes of
//! a regular file and verifies every complete line before anything is
//! resumed: its record, its place in the hash chain, and the header's
//! `config_digest`. A flipped bit anywhere (an `episode_end` before the
//! last checkpoint included), an edited checkpoint, removed or reordered
//! lines, a header spliced from another log, or an edited config are
//! refused with the line at fault. The chain has no key: it catches
//! corruption and edits, not a forger who recomputes it.
//!
//! # Resuming
//!
//! A session killed at any point (even `kill -9`) is continued by
//! [`run_recorded`] with the log's [`LoggedSession`]:
//!
//! 1. an incomplete last line (a write cut short) is discarded; since a step
//!    is on disk before the robot acts, the robot never acted on it;
//! 2. the policy is restored from the last checkpoint, and the episodes
//!    before it are not re-run;
//! 3. the rest is re-run deterministically from the logged seed: queries
//!    already answered get the person's logged answers (nobody is asked
//!    twice), and every record the replay produces must equal the logged
//!    one byte for byte, or resuming stops with an error naming the line;
//! 4. from the end of the log on, the session runs live and appends.
//!
//! So no step is lost or duplicated, and the continuation is the one an
//! uninterrupted run with the same seed produces. A step logged without its
//! outcome (killed while the robot acted) is executed again; in simulation
//! that reproduces the same outcome.
//!
//! Replaying calls the environment again for the steps of the unfinished
//! episode, so it needs an environment that is deterministic given its seed
//! (every simulated one is). A physical robot would repeat those actions
//! and observe new contexts, which the verification rejects: resuming
//! real-robot sessions needs an environment-side replay mode, which does
//! not exist yet.
//!
//! ```
//! use hil_core::record::{Header, RecordLog, Recorder, Record};
//! let dir = std::env::temp_dir().join(format!("hil-record-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("session.jsonl");
//! # let _ = std::fs::remove_file(&path);
//! let log = RecordLog::create(&path, Header::new("seed = 1", "exp.toml", ".", 1, 1)).unwrap();
//! let mut rec = Recorder::new(log);
//! rec.emit(&Record::EpisodeStart { episode: 0, seed: 9 }).unwrap();
//! // One writer at a time: the recorder still holds the log.
//! assert!(RecordLog::open(&path).is_err());
//! drop(rec);
//! let (_, logged) = RecordLog::open(&path).unwrap();
//! assert_eq!(logged.header.seed, 1);
//! assert_eq!(logged.records.len(), 1);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

pub mod chain;
pub mod format;
pub mod lock;
pub mod log;
pub mod recorder;
mod replay;

use std::collections::VecDeque;

use crate::error::{HilError, Result};
use crate::experiment::{Experiment, ExperimentSummary};
use crate::metrics::EpisodeMetrics;
use crate::session::{Session, SessionObserver, StepEvent};

pub use format::{FORMAT_NAME, FORMAT_VERSION, Header, Record};
pub use log::{LoggedRecord, LoggedSession, RecordLog};
pub use recorder::Recorder;

use replay::{LoggedAnswer, ReplayChannel};

impl LoggedSession {
    /// The completed steps of the log, as `(episode, event)`, in order.
    /// A step whose outcome was not logged is left out.
    pub fn events(&self) -> Vec<(usize, StepEvent)> {
        let mut out = Vec::new();
        let mut pending = None;
        for r in &self.records {
            match &r.record {
                Record::Step { episode, step } => pending = Some((*episode, step.clone())),
                Record::Outcome {
                    episode,
                    t,
                    outcome,
                } => {
                    if let Some((e, step)) = pending.take()
                        && e == *episode
                        && step.t == *t
                    {
                        out.push((
                            e,
                            StepEvent {
                                step,
                                outcome: outcome.clone(),
                            },
                        ));
                    }
                }
                _ => {}
            }
        }
        out
    }
}

/// Where a resumed session starts, derived from its log.
struct ResumePlan {
    start_episode: usize,
    /// The checkpoint to restore: its episode, state and log line.
    restore: Option<(usize, serde_json::Value, usize)>,
    metrics_before: Vec<EpisodeMetrics>,
    expected: Vec<LoggedRecord>,
    answers: VecDeque<LoggedAnswer>,
}

fn plan(session: &LoggedSession, log: &RecordLog) -> Result<ResumePlan> {
    let data_err = |line: usize, field: &str, why: String| HilError::Data {
        path: log.path().to_path_buf(),
        record: line,
        field: field.to_string(),
        why,
    };
    // The last checkpoint whose episode ends are all present.
    let mut ends: Vec<EpisodeMetrics> = Vec::new();
    let mut cut = None;
    for (i, r) in session.records.iter().enumerate() {
        match &r.record {
            Record::EpisodeEnd { episode, metrics } => {
                if *episode != ends.len() {
                    return Err(data_err(
                        r.line,
                        "episode",
                        format!(
                            "episode {episode} ends where episode {} was expected",
                            ends.len()
                        ),
                    ));
                }
                ends.push(metrics.clone());
            }
            Record::Checkpoint { episode, policy } if *episode + 1 == ends.len() => {
                cut = Some((i, *episode, policy.clone(), r.line));
            }
            _ => {}
        }
    }
    let (first, start_episode, restore, metrics_before) = match cut {
        Some((i, k, state, line)) => (i + 1, k + 1, Some((k, state, line)), ends[..=k].to_vec()),
        None => (0, 0, None, Vec::new()),
    };
    let expected: Vec<LoggedRecord> = session.records[first..]
        .iter()
        .filter(|r| !matches!(r.record, Record::Resumed { .. }))
        .cloned()
        .collect();
    let answers = expected
        .iter()
        .filter_map(|r| match &r.record {
            Record::Step { episode, step } => step
                .response
                .clone()
                .map(|resp| (*episode, step.t, resp, r.line)),
            _ => None,
        })
        .collect();
    Ok(ResumePlan {
        start_episode,
        restore,
        metrics_before,
        expected,
        answers,
    })
}

/// Runs `exp`, recording every step into `log`; with `resume` (the log's
/// contents, from [`RecordLog::open`]), continues the logged session
/// instead. `on_episode` is called with each episode's number and metrics,
/// including episodes restored from the log.
///
/// See the [module documentation](self) for the guarantees.
pub fn run_recorded(
    exp: &mut Experiment,
    log: RecordLog,
    resume: Option<&LoggedSession>,
    observers: &mut [&mut dyn SessionObserver],
    mut on_episode: impl FnMut(usize, &EpisodeMetrics),
) -> Result<ExperimentSummary> {
    let path = log.path().to_path_buf();
    let (mut recorder, plan) = match resume {
        None => (
            Recorder::new(log),
            ResumePlan {
                start_episode: 0,
                restore: None,
                metrics_before: Vec::new(),
                expected: Vec::new(),
                answers: VecDeque::new(),
            },
        ),
        Some(session) => {
            if session.header.episodes != exp.episodes || session.header.seed != exp.seed {
                return Err(HilError::Data {
                    path,
                    record: 1,
                    field: "header".into(),
                    why: format!(
                        "the log is for seed {} and {} episode(s), the experiment has seed {} and {}",
                        session.header.seed, session.header.episodes, exp.seed, exp.episodes
                    ),
                });
            }
            let mut plan = plan(session, &log)?;
            let marker = Record::Resumed {
                lines: log.lines(),
                truncated_bytes: session.truncated_bytes,
                from_checkpoint: plan.restore.as_ref().map(|(k, _, _)| *k),
            };
            let expected = std::mem::take(&mut plan.expected);
            (Recorder::resuming(log, expected, marker), plan)
        }
    };
    if let Some((k, state, line)) = plan.restore {
        exp.policy.restore(state).map_err(|e| HilError::Data {
            path: path.clone(),
            record: line,
            field: format!("checkpoint of episode {k}"),
            why: format!("the policy could not restore it: {e}"),
        })?;
    }
    let mut metrics = plan.metrics_before;
    for (k, m) in metrics.iter().enumerate() {
        on_episode(k, m);
    }
    let seeds: Vec<u64> = (0..exp.episodes).map(|k| exp.episode_seed(k)).collect();
    let mut channel = ReplayChannel {
        inner: exp.channel.as_mut(),
        logged: plan.answers,
        episode: 0,
        path: path.clone(),
    };
    for (k, &seed) in seeds.iter().enumerate().skip(plan.start_episode) {
        recorder.set_episode(k);
        channel.episode = k;
        let mut session = Session {
            settings: exp.settings.clone(),
            environment: exp.environment.as_mut(),
            policy: exp.policy.as_mut(),
            channel: &mut channel,
            workload: exp.workload.clone(),
            forecast: exp.forecast.clone(),
        };
        let mut all: Vec<&mut dyn SessionObserver> = Vec::with_capacity(observers.len() + 1);
        all.push(&mut recorder);
        for o in observers.iter_mut() {
            all.push(&mut **o);
        }
        let report = session.run_episode(seed, &mut all)?;
        // Checkpoint the policy at the episode boundary, where nothing else
        // carries over (environment, channel and workload are reseeded).
        if let Ok(state) = exp.policy.save() {
            recorder.emit(&Record::Checkpoint {
                episode: k,
                policy: state,
            })?;
        }
        on_episode(k, &report.metrics);
        metrics.push(report.metrics);
    }
    if let Some(extra) = recorder.next_expected() {
        return Err(HilError::Data {
            path,
            record: extra.line,
            field: extra.record.kind().to_string(),
            why: "the log continues past the end of the session the config describes".into(),
        });
    }
    Ok(ExperimentSummary::new(metrics))
}
