//! The interaction record: every step of a session in a JSONL log that
//! survives a crash, and resuming a session from it.
//!
//! # Format
//!
//! One JSON object per line, tagged by its `record` field (see [`Record`]).
//! Every line starts with a `chain` field, the SHA-256 (in a keyed log, the
//! HMAC-SHA256) of the previous line's `chain` and the line's own content
//! ([`chain`]), which makes the log tamper-evident.
//!
//! | record | when | fields |
//! |---|---|---|
//! | `header` | first line | `format` (`hil-interaction-record`), `version` (3), `seed`, `episodes`, `config_path`, `base_dir`, `config` (the experiment TOML, verbatim), `config_digest` (its SHA-256), and in a keyed log `record_key` (the key's id) |
//! | `episode_start` | episode begins | `episode`, `seed` |
//! | `step` | decided, **fsync'ed before the robot acts** | `episode`, `step`: `t`, `item_index`, `item_label`, `attempt`, `context`, `decision` (`act` / `query` with its `kind` = response type, difficulty, distraction, and `fallback` / `follow_expert`), `diagnostics`, `response` (answer, expert arm, response time; a `timed_out` answer means the policy acted on its own), `arm`, `wl_t` (WL_t = f(WL_0, Q_t) at this step) |
//! | `outcome` | after execution, fsync'ed | `episode`, `t`, `outcome` (`success`, `success_probability`) |
//! | `episode_end` | episode ends | `episode`, `metrics` |
//! | `checkpoint` | after `episode_end`, if the policy can save its state | `episode`, `policy` (its [`hil_core::Policy::save`]) |
//! | `resumed` | where a resumed session started appending | `lines`, `truncated_bytes`, `from_checkpoint` (always null now: every resume replays from the start) |
//!
//! # One writer, and tamper evidence
//!
//! A [`RecordLog`] holds an exclusive lock on its file for as long as it
//! lives ([`lock`]): a second writer, such as a second `hil run --resume` or
//! a resume while the original run still writes, is refused with an error
//! naming the process, host and start time of the holder.
//!
//! [`RecordLog::open`] reads at most [`hil_core::files::limits::LOG`] bytes of
//! a regular file and verifies every complete line before anything is
//! resumed: its record, its place in the hash chain, and the header's
//! `config_digest`. A flipped bit anywhere (an `episode_end` before the
//! last checkpoint included), an edited checkpoint, removed or reordered
//! lines, a header spliced from another log, or an edited config are
//! refused with the line at fault. An unkeyed chain catches corruption
//! and edits, not a forger who recomputes it; a keyed one
//! ([`RecordLog::create_with_key`], [`key`]) is chained with HMAC-SHA256
//! under a secret key kept outside the log, so only a key holder can
//! re-chain it. The header names the key's id: a keyed log is opened only
//! with its key ([`RecordLog::open_with_key`]), and a key is refused for an
//! unkeyed log.
//!
//! # Resuming
//!
//! A session killed at any point (even `kill -9`) is continued by
//! `hil_experiments::run_recorded` with the log's [`LoggedSession`]
//! (this module holds the log, the [`Recorder`] and the [`ReplayChannel`]
//! it runs with):
//!
//! 1. an incomplete last line (a write cut short) is discarded; since a step
//!    is on disk before the robot acts, the robot never acted on it;
//! 2. the whole session is re-run from the header's config and seed (a
//!    checkpoint is checked like any record, not trusted: so an episode
//!    summary that disagrees with its steps, or a header whose config was
//!    changed, is refused even when the chain was recomputed);
//! 3. it is re-run deterministically from the logged seed: queries
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
//! use hil_record::{Header, RecordLog, Recorder, Record};
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
pub mod key;
pub mod lock;
pub mod log;
pub mod recorder;
pub mod replay;

use hil_core::event::StepEvent;

pub use format::{FORMAT_NAME, FORMAT_VERSION, Header, Record};
pub use key::RecordKey;
pub use log::{LoggedRecord, LoggedSession, RecordLog};
pub use recorder::Recorder;

pub use replay::{LoggedAnswer, ReplayChannel};

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
