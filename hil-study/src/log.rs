//! Each participant's raw event log: one JSON object per line, appended and
//! fsync'ed before the page hears "saved", numbered so that a lost or
//! repeated line is detected. A last line cut short by a crash is dropped
//! on opening (it was never acknowledged).

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use hil_core::{Answer, Difficulty, HilError, ResponseType, Result};
use hil_workload::study::Population;
use hil_workload::tlx::TlxAnswers;
use serde::{Deserialize, Serialize};

/// What happened, as logged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case", deny_unknown_fields)]
pub enum Event {
    /// First line: who (pseudonymously) and in which order.
    Enrolled {
        /// Pseudonymous id (`p001`, ...).
        participant: String,
        /// Population.
        population: Population,
        /// 0-based enrolment number (sets the counterbalanced order).
        number: usize,
        /// The participant's secret link token.
        token: String,
        /// Condition ids in the order this participant takes them.
        order: Vec<String>,
    },
    /// The participant started a condition.
    ConditionStarted {
        /// Condition id.
        condition: String,
    },
    /// A robot query appeared.
    QueryShown {
        /// Condition id.
        condition: String,
        /// Query number within the condition (0-based).
        query: usize,
        /// Study seconds on the task clock when it appeared.
        task_s: f64,
        /// Its difficulty.
        difficulty: Difficulty,
        /// Its response type.
        response: ResponseType,
    },
    /// The participant answered a query.
    QueryAnswered {
        /// Condition id.
        condition: String,
        /// Query number.
        query: usize,
        /// Study seconds on the task clock.
        task_s: f64,
        /// The answer.
        answer: Answer,
        /// Real seconds from the query appearing (on this server run).
        response_time_s: f64,
        /// For a choice: whether it was right.
        correct: Option<bool>,
        /// For a box: its overlap with the item's box.
        iou: Option<f64>,
    },
    /// A TLX survey was submitted.
    SurveySubmitted {
        /// Condition id.
        condition: String,
        /// The query it follows, or `None` at the end of the condition.
        query: Option<usize>,
        /// Study seconds on the task clock (paused during the survey).
        task_s: f64,
        /// The answers (1..=5).
        tlx: TlxAnswers,
        /// Real seconds from the survey appearing to its submission.
        survey_time_s: f64,
    },
    /// An answer to the distraction task.
    DistractionAnswered {
        /// Condition id.
        condition: String,
        /// Study seconds on the task clock.
        task_s: f64,
        /// Sum number or line number.
        index: usize,
        /// What was typed.
        answer: String,
        /// For a sum: whether it was right.
        correct: Option<bool>,
    },
    /// The server was restarted or the participant came back after being
    /// away; the task clock continues from `task_s`.
    Resumed {
        /// The condition in progress, if any.
        condition: Option<String>,
        /// Study seconds on the task clock.
        task_s: f64,
        /// On a server restart, what was read back from this log (absent
        /// when the participant came back after being away).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        replayed: Option<Replayed>,
    },
}

/// What a restarted server read back from a participant's log.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Replayed {
    /// Whole lines replayed (the `enrolled` line included).
    pub lines: usize,
    /// Whether a last line cut short (by a crash mid-write) was dropped.
    pub dropped_cut_short_line: bool,
}

/// A logged line: its number, when it was written, the event.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Line {
    /// 0-based line number.
    pub seq: usize,
    /// Milliseconds since the Unix epoch when it was written.
    pub unix_ms: u64,
    /// What happened.
    #[serde(flatten)]
    pub event: Event,
}

/// An open log, appending.
#[derive(Debug)]
pub struct EventLog {
    file: File,
    path: PathBuf,
    next_seq: usize,
}

/// Largest participant log read (the study's logs are kilobytes).
pub const MAX_LOG_BYTES: u64 = 64 << 20;

/// Reads every complete line of the log at `path`. Returns the lines and
/// the byte length of the complete part (a cut-short last line excluded).
pub fn read(path: &Path) -> Result<(Vec<Line>, usize)> {
    let text = hil_core::files::read_text(path, MAX_LOG_BYTES)?;
    let complete = text.rfind('\n').map_or(0, |i| i + 1);
    let mut lines = Vec::new();
    for (i, l) in text[..complete].lines().enumerate() {
        let line: Line = serde_json::from_str(l).map_err(|e| {
            hil_textdata::data_error(path, i + 1, "event", format!("not a study event: {e}"))
        })?;
        if line.seq != i {
            return Err(hil_textdata::data_error(
                path,
                i + 1,
                "seq",
                format!(
                    "is {}, expected {i}: a line is missing or repeated",
                    line.seq
                ),
            ));
        }
        lines.push(line);
    }
    Ok((lines, complete))
}

impl EventLog {
    /// Creates a new log at `path` (refused if it exists) with `first`.
    pub fn create(path: &Path, first: Event) -> Result<Self> {
        let mut options = OpenOptions::new();
        options.create_new(true).append(true);
        // The log holds the participant's link token and answers: the
        // owner's only, like the researcher's token.
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
        let file = options
            .open(path)
            .map_err(|e| HilError::io("creating", path, e))?;
        let mut log = Self {
            file,
            path: path.to_path_buf(),
            next_seq: 0,
        };
        log.append(first)?;
        // The new file's name must survive a crash too.
        if let Some(dir) = path.parent()
            && let Ok(d) = File::open(dir)
        {
            let _ = d.sync_all();
        }
        Ok(log)
    }

    /// Opens an existing log for appending; drops a cut-short last line.
    /// Also says what was read back ([`Replayed`]).
    pub fn open(path: &Path) -> Result<(Self, Vec<Line>, Replayed)> {
        let (lines, complete) = read(path)?;
        let file = OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| HilError::io("opening", path, e))?;
        let len = file
            .metadata()
            .map_err(|e| HilError::io("reading", path, e))?
            .len();
        let cut_short = len != complete as u64;
        if cut_short {
            file.set_len(complete as u64)
                .map_err(|e| HilError::io("truncating a cut-short line of", path, e))?;
            file.sync_all()
                .map_err(|e| HilError::io("syncing", path, e))?;
        }
        let replayed = Replayed {
            lines: lines.len(),
            dropped_cut_short_line: cut_short,
        };
        Ok((
            Self {
                file,
                path: path.to_path_buf(),
                next_seq: lines.len(),
            },
            lines,
            replayed,
        ))
    }

    /// Appends `event` and waits until it is on disk.
    pub fn append(&mut self, event: Event) -> Result<Line> {
        let unix_ms = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_millis() as u64);
        let line = Line {
            seq: self.next_seq,
            unix_ms,
            event,
        };
        let mut text =
            serde_json::to_string(&line).map_err(|e| HilError::serde("study event", e))?;
        text.push('\n');
        let len = self
            .file
            .metadata()
            .map_err(|e| HilError::io("reading", &self.path, e))?
            .len();
        if let Err(e) = self
            .file
            .write_all(text.as_bytes())
            .and_then(|()| self.file.sync_data())
        {
            // Take back a part-written line, so the next one starts clean.
            let _ = self.file.set_len(len);
            return Err(HilError::io("appending to", &self.path, e));
        }
        self.next_seq += 1;
        Ok(line)
    }

    /// The log's file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
