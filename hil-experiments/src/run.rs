//! Running an experiment with its interaction record, or resuming one from
//! its log: the flow `hil run` and hil-py's `hil.run`, `hil.resume` and
//! `hil.run_session` share.
//!
//! - [`Run::from_config`] reads, parses and builds an experiment file and,
//!   given a log path, creates that log (it must not exist yet) under a
//!   header holding the config verbatim with its absolute path and base
//!   directory, so that a resume from any directory finds the same files.
//! - [`Run::resume`] opens a log (taking its one-writer lock and verifying
//!   every line, [`RecordLog::open`]) and builds the experiment from the
//!   config its header holds.
//! - [`Run::execute`] runs every episode, through
//!   [`hil_experiments::run_recorded`] when there is a log.
//!
//! ```
//! use hil_experiments::run::Run;
//! let dir = std::env::temp_dir().join(format!("hil-run-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let config = dir.join("exp.toml");
//! std::fs::write(&config, r#"
//! seed = 3
//! [session]
//! max_items = 2
//! [environment]
//! type = "demo_plate"
//! foods = ["banana", "carrot"]
//! [policy]
//! type = "linucb_qg"
//! alpha = 0.5
//! w = 1.0
//! [workload]
//! type = "bundled"
//! name = "f12_sim"
//! [channel]
//! type = "simulated_expert"
//! "#).unwrap();
//! let log = dir.join("session.jsonl");
//! # let _ = std::fs::remove_file(&log);
//! let first = Run::from_config(&config, Some(&log)).unwrap().execute(&mut [], |_, _| {}).unwrap();
//! // A finished log resumes to the same summary.
//! let again = Run::resume(&log).unwrap().execute(&mut [], |_, _| {}).unwrap();
//! assert_eq!(again.episodes, first.episodes);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use hil_core::{EpisodeMetrics, HilError, Result, SessionObserver, StepEvent};
use hil_record::{Header, LoggedSession, RecordKey, RecordLog};

use crate::{Experiment, ExperimentSummary, run_recorded};

/// Where a run's steps are recorded.
#[derive(Debug)]
pub enum Recording {
    /// Nowhere.
    Off,
    /// In a new interaction log.
    New(RecordLog),
    /// Appended to an interaction log, continuing the session it records.
    Resume(RecordLog, Box<LoggedSession>),
}

impl Recording {
    /// Records into a new log at `path` (it must not exist yet) under
    /// `header`.
    pub fn create(path: &Path, header: Header) -> Result<Self> {
        Self::create_with_key(path, header, None)
    }

    /// [`Recording::create`], with the log keyed by `key` if given
    /// ([`RecordLog::create_with_key`]).
    pub fn create_with_key(path: &Path, header: Header, key: Option<RecordKey>) -> Result<Self> {
        Ok(Self::New(RecordLog::create_with_key(path, header, key)?))
    }

    /// Continues the session recorded at `path`: opens the log, holding
    /// its one-writer lock from now on, and verifies every line.
    pub fn open(path: &Path) -> Result<Self> {
        Self::open_with_key(path, None)
    }

    /// [`Recording::open`] for a log that may be keyed: `key` must be its
    /// key ([`RecordLog::open_with_key`]).
    pub fn open_with_key(path: &Path, key: Option<RecordKey>) -> Result<Self> {
        let (log, logged) = RecordLog::open_with_key(path, key)?;
        Ok(Self::Resume(log, Box::new(logged)))
    }

    /// The logged session being resumed, if any.
    pub fn logged(&self) -> Option<&LoggedSession> {
        match self {
            Self::Resume(_, logged) => Some(logged),
            Self::Off | Self::New(_) => None,
        }
    }

    /// The log's path, if the run is recorded.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Self::Off => None,
            Self::New(log) | Self::Resume(log, _) => Some(log.path()),
        }
    }
}

/// An experiment built and ready to run, with where its steps go.
#[derive(Debug)]
pub struct Run {
    /// The built components.
    pub experiment: Experiment,
    /// Where its steps are recorded.
    pub recording: Recording,
}

/// The refusal of a record key given without a log: there is nothing to
/// key, and running unrecorded would drop what the caller asked for.
pub fn key_without_log(key: &RecordKey) -> HilError {
    HilError::invalid_input(
        "record key",
        format!(
            "a record key ({}) was given but no log to key",
            key.path().display()
        ),
    )
}

impl Run {
    /// Reads the experiment file `config`, builds it (relative paths
    /// resolve against its directory) and, with `log`, records into a new
    /// interaction log there.
    pub fn from_config(config: &Path, log: Option<&Path>) -> Result<Self> {
        Self::from_config_with_key(config, log, None)
    }

    /// [`Run::from_config`], with the log keyed by `key` if given (a key
    /// without a log is refused: there is nothing to key).
    pub fn from_config_with_key(
        config: &Path,
        log: Option<&Path>,
        key: Option<RecordKey>,
    ) -> Result<Self> {
        if log.is_none()
            && let Some(key) = &key
        {
            return Err(key_without_log(key));
        }
        let text = hil_core::files::read_text(config, hil_core::files::limits::CONFIG)?;
        let cfg = crate::parse_experiment(&text, config)?;
        // Absolute, so that a resume from another directory finds the
        // same files; made absolute before taking the directory, which for
        // a bare file name (`exp.toml`) is empty.
        let config_abs =
            std::path::absolute(config).map_err(|e| HilError::io("resolving", config, e))?;
        let base = config_abs
            .parent()
            .map_or_else(|| config_abs.clone(), Path::to_path_buf);
        let experiment = cfg.build_located(&base, &text, config)?;
        let recording = match log {
            Some(path) => {
                let header = Header::new(
                    &text,
                    config_abs,
                    base,
                    experiment.seed,
                    experiment.episodes,
                );
                Recording::create_with_key(path, header, key)?
            }
            None => Recording::Off,
        };
        Ok(Self {
            experiment,
            recording,
        })
    }

    /// Continues the session recorded in `log` ([`Recording::open`]),
    /// built from the config its header holds.
    pub fn resume(log: &Path) -> Result<Self> {
        Self::resume_with_key(log, None)
    }

    /// [`Run::resume`] of a log that may be keyed: `key` must be its key.
    pub fn resume_with_key(log: &Path, key: Option<RecordKey>) -> Result<Self> {
        Self::resume_from(Recording::open_with_key(log, key)?)
    }

    /// Continues the session `recording` resumes (from
    /// [`Recording::open`]; a caller may look at its header first), built
    /// from the config its header holds.
    pub fn resume_from(recording: Recording) -> Result<Self> {
        let Some(logged) = recording.logged() else {
            return Err(HilError::invalid_input(
                "recording",
                "only a recording opened from a log can be resumed",
            ));
        };
        let header = &logged.header;
        let cfg = crate::parse_experiment(&header.config, &header.config_path)?;
        let experiment =
            cfg.build_located(&header.base_dir, &header.config, &header.config_path)?;
        Ok(Self {
            experiment,
            recording,
        })
    }

    /// Runs every episode (the rest of them, resuming), reporting to
    /// `observers` and calling `on_episode` with each episode's number and
    /// metrics (including episodes restored from the log).
    pub fn execute(
        mut self,
        observers: &mut [&mut dyn SessionObserver],
        on_episode: impl FnMut(usize, &EpisodeMetrics),
    ) -> Result<ExperimentSummary> {
        run_with(&mut self.experiment, self.recording, observers, on_episode)
    }
}

/// Runs `experiment` as `recording` says: see [`Run::execute`]. For an
/// experiment built in code (hil-py's `run_session`).
pub fn run_with(
    experiment: &mut Experiment,
    recording: Recording,
    observers: &mut [&mut dyn SessionObserver],
    mut on_episode: impl FnMut(usize, &EpisodeMetrics),
) -> Result<ExperimentSummary> {
    match recording {
        Recording::Off => experiment.run(observers, |k, r| on_episode(k, &r.metrics)),
        Recording::New(log) => run_recorded(experiment, log, None, observers, on_episode),
        Recording::Resume(log, logged) => {
            run_recorded(experiment, log, Some(&logged), observers, on_episode)
        }
    }
}

/// Writes every step event as a JSON line to a file.
#[derive(Debug)]
pub struct JsonlEvents {
    path: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
}

impl JsonlEvents {
    /// Creates (or truncates) the file at `path`.
    pub fn create(path: &Path) -> Result<Self> {
        let file = std::fs::File::create(path).map_err(|e| HilError::io("creating", path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: std::io::BufWriter::new(file),
        })
    }

    /// Writes out what is buffered; an error names the file.
    pub fn finish(mut self) -> Result<()> {
        self.out
            .flush()
            .map_err(|e| HilError::io("writing", &self.path, e))
    }
}

impl SessionObserver for JsonlEvents {
    fn on_step(&mut self, event: &StepEvent) -> Result<()> {
        // Serialised apart from writing, so that a failing file (a full
        // disk, /dev/full) is reported as an I/O error naming it.
        let mut line = serde_json::to_vec(event).map_err(|e| HilError::serde("step event", e))?;
        line.push(b'\n');
        self.out
            .write_all(&line)
            .map_err(|e| HilError::io("writing", &self.path, e))
    }
}
