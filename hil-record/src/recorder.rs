//! The observer that writes the log, or, while a resumed session replays
//! what the log already holds, checks the replay against it.

use std::collections::VecDeque;

use crate::format::Record;
use crate::log::{LoggedRecord, RecordLog};
use hil_core::error::{HilError, Result};
use hil_core::metrics::EpisodeMetrics;
use hil_core::session::{PendingStep, SessionObserver, StepEvent};

/// Writes every session event to a [`RecordLog`]. Steps are on disk before
/// the robot acts ([`SessionObserver::before_execute`]), outcomes as soon as
/// they are known.
///
/// When resuming, the records already in the log are *expected*: each record
/// the replayed session produces is compared, byte for byte, with the next
/// logged one instead of being written, so a replay that diverges from the
/// log stops with an error naming the line; once the log is exhausted,
/// records are appended again.
#[derive(Debug)]
pub struct Recorder {
    log: RecordLog,
    expected: VecDeque<LoggedRecord>,
    marker: Option<Record>,
    episode: usize,
}

impl Recorder {
    /// Records a new session into `log`.
    pub fn new(log: RecordLog) -> Self {
        Self {
            log,
            expected: VecDeque::new(),
            marker: None,
            episode: 0,
        }
    }

    /// Continues `log`: `expected` records are verified rather than written,
    /// and `marker` is written before the first new record.
    pub fn resuming(log: RecordLog, expected: Vec<LoggedRecord>, marker: Record) -> Self {
        Self {
            log,
            expected: expected.into(),
            marker: Some(marker),
            episode: 0,
        }
    }

    /// Sets the episode number stamped on the next records.
    pub fn set_episode(&mut self, episode: usize) {
        self.episode = episode;
    }

    /// True while logged records remain to be verified.
    pub fn replaying(&self) -> bool {
        !self.expected.is_empty()
    }

    /// The first logged record not yet matched by the replay, if any.
    pub fn next_expected(&self) -> Option<&LoggedRecord> {
        self.expected.front()
    }

    /// The underlying log.
    pub fn log(&self) -> &RecordLog {
        &self.log
    }

    /// Writes `record` (or verifies it against the log while replaying).
    pub fn emit(&mut self, record: &Record) -> Result<()> {
        let text = serde_json::to_string(record)
            .map_err(|e| HilError::serde(format!("{} record", record.kind()), e))?;
        // JSON has no NaN or infinity (serde_json writes them as null): a
        // record that does not read back would make the log unresumable,
        // so it stops the session before the robot acts. The session loop
        // checks what components return first; this catches the rest.
        if let Err(e) = serde_json::from_str::<Record>(&text) {
            return Err(HilError::invalid_input(
                format!("{} record of episode {}", record.kind(), self.episode),
                format!(
                    "it contains a number a log cannot hold (NaN or infinity, written as \
                     null): {e}"
                ),
            ));
        }
        if let Some(logged) = self.expected.pop_front() {
            if logged.text != text {
                return Err(HilError::Data {
                    path: self.log.path().to_path_buf(),
                    record: logged.line,
                    field: logged.record.kind().to_string(),
                    why: format!(
                        "the resumed session diverged from the log (was a plugin, a file the \
                         config names, or the code changed?): the log has\n  {}\nbut the replay \
                         produced\n  {text}",
                        logged.text
                    ),
                });
            }
            return Ok(());
        }
        if let Some(marker) = self.marker.take() {
            self.log.append(&marker)?;
        }
        self.log.append_text(&text)
    }
}

impl SessionObserver for Recorder {
    fn on_episode_start(&mut self, seed: u64) -> Result<()> {
        self.emit(&Record::EpisodeStart {
            episode: self.episode,
            seed,
        })
    }

    fn before_execute(&mut self, step: &PendingStep) -> Result<()> {
        self.emit(&Record::Step {
            episode: self.episode,
            step: step.clone(),
        })
    }

    fn on_step(&mut self, event: &StepEvent) -> Result<()> {
        self.emit(&Record::Outcome {
            episode: self.episode,
            t: event.step.t,
            outcome: event.outcome.clone(),
        })
    }

    fn on_episode_end(&mut self, metrics: &EpisodeMetrics) -> Result<()> {
        self.emit(&Record::EpisodeEnd {
            episode: self.episode,
            metrics: metrics.clone(),
        })
    }
}
