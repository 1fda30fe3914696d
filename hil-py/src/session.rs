//! The session loop from Python, with its interaction record and resume,
//! as `hil run` drives it: from an experiment file (`hil.run`,
//! `hil.resume`) or from components given in code (`hil.run_session`,
//! any of them Python objects). The GIL is released while it runs, and
//! Ctrl-C stops it between two steps ([`crate::interrupt`]), the log then
//! holding every step so far.

use std::path::PathBuf;

use hil_core::{EventCollector, HilError, SessionObserver, SessionSettings};
use hil_experiments::run::{Recording, Run, key_without_log, run_with};
use hil_experiments::{Experiment, ExperimentSummary};
use hil_record::{Header, RecordKey};
use pyo3::prelude::*;

use crate::components::{channel_arg, environment_arg, policy_arg, workload_arg};
use crate::convert::to_py;
use crate::errors::IntoPy;
use crate::interrupt::StopAtBoundary;

/// The config text a component session's log header holds: its
/// components were given in code, so a resume gives them again.
const CODE_SESSION: &str =
    "# a session whose components were given in Python code (hil.run_session)\n";

/// Runs `exp` as `recording` says on a worker thread, with the GIL
/// released; Ctrl-C (or any exception a signal handler raises) stops it at
/// the next boundary between steps and is raised here, the interaction log
/// holding every step so far (see [`crate::interrupt`]).
fn drive(
    py: Python<'_>,
    mut exp: Experiment,
    recording: Recording,
    events: bool,
) -> PyResult<Py<PyAny>> {
    let (summary, collector) = crate::interrupt::run(py, None, "session", move |control| {
        let mut collector = EventCollector::default();
        let mut stopper = StopAtBoundary(control);
        let mut observers: Vec<&mut dyn SessionObserver> = Vec::new();
        if events {
            observers.push(&mut collector);
        }
        observers.push(&mut stopper);
        let summary = run_with(&mut exp, recording, &mut observers, |_, _| {});
        drop(observers);
        (summary, collector)
    })?;
    let summary: ExperimentSummary = summary.py_err()?;
    let out = to_py(py, &summary, "summary")?;
    if events {
        out.bind(py)
            .set_item("events", to_py(py, &collector.events, "step events")?)?;
    }
    Ok(out)
}

/// The key file `record_key` names (`hil record keygen` writes one), read
/// and checked: owner-only, one line of hex, long enough.
fn read_key(record_key: Option<PathBuf>) -> PyResult<Option<RecordKey>> {
    record_key
        .as_deref()
        .map(RecordKey::read)
        .transpose()
        .py_err()
}

/// Runs the experiment file `config` (TOML, as `hil run --config`) and
/// returns its summary (the serde form of `ExperimentSummary`: per-episode
/// metrics, means and standard deviations). With `log`, every step is
/// recorded in that interaction log (it must not exist yet), so a killed
/// run continues with `resume(log)`; with `record_key` (a key file, as
/// `hil run --record-key`) the log is keyed, so an edit is caught even if
/// its chain is recomputed. With `events=True` the summary also holds
/// every step event.
#[pyfunction]
#[pyo3(signature = (config, *, log=None, record_key=None, events=false))]
pub(crate) fn run(
    py: Python<'_>,
    config: PathBuf,
    log: Option<PathBuf>,
    record_key: Option<PathBuf>,
    events: bool,
) -> PyResult<Py<PyAny>> {
    let key = read_key(record_key)?;
    let run = py
        .detach(|| Run::from_config_with_key(&config, log.as_deref(), key))
        .py_err()?;
    drive(py, run.experiment, run.recording, events)
}

/// Continues the session recorded in `log` by `run(config, log=...)` (after
/// a crash, a kill or an interrupt): the config comes from the log,
/// answered queries are not asked again, new steps are appended. A keyed
/// log needs its `record_key`. Returns the summary of the whole session.
#[pyfunction]
#[pyo3(signature = (log, *, record_key=None, events=false))]
pub(crate) fn resume(
    py: Python<'_>,
    log: PathBuf,
    record_key: Option<PathBuf>,
    events: bool,
) -> PyResult<Py<PyAny>> {
    let recording = Recording::open_with_key(&log, read_key(record_key)?).py_err()?;
    if recording
        .logged()
        .is_some_and(|l| l.header.config == CODE_SESSION)
    {
        return Err(crate::errors::to_py_err(HilError::invalid_input(
            "log",
            format!(
                "{} records a session whose components were given in code: resume it with run_session(..., resume=LOG) and the same components",
                log.display()
            ),
        )));
    }
    let run = py.detach(|| Run::resume_from(recording)).py_err()?;
    drive(py, run.experiment, run.recording, events)
}

/// Runs `episodes` episodes of hil's session loop over components given in
/// code, each a hil object (`hil.Policy`, `hil.Environment`,
/// `hil.QueryChannel`, `hil.WorkloadModel` or a bundled model's name) or
/// a Python object with the right methods. `channel=None` is the paper's
/// perfect expert; `forecast` is the model the policy forecasts with, if
/// not `workload`. Returns the summary as `run` does. `log` records every
/// step; `resume=LOG` continues a session so recorded, given the same
/// components; `record_key` keys the log (or opens a keyed one).
#[pyfunction]
#[pyo3(signature = (*, environment, policy, workload, channel=None, forecast=None, episodes=1, seed=0, n_att=10, wl0=0.5, max_items=None, log=None, resume=None, record_key=None, events=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_session(
    py: Python<'_>,
    environment: &Bound<'_, PyAny>,
    policy: &Bound<'_, PyAny>,
    workload: &Bound<'_, PyAny>,
    channel: Option<&Bound<'_, PyAny>>,
    forecast: Option<&Bound<'_, PyAny>>,
    episodes: usize,
    seed: u64,
    n_att: u32,
    wl0: f64,
    max_items: Option<usize>,
    log: Option<PathBuf>,
    resume: Option<PathBuf>,
    record_key: Option<PathBuf>,
    events: bool,
) -> PyResult<Py<PyAny>> {
    let settings = SessionSettings::default()
        .with_n_att(n_att)
        .with_wl0(wl0)
        .with_max_items(max_items);
    // Before a log is created (Experiment::run checks again for Rust callers).
    settings.validate().py_err()?;
    hil_config::check_session_limits(&settings).py_err()?;
    let (environment, _) = environment_arg(environment)?;
    let exp = Experiment {
        settings,
        seed,
        episodes,
        environment,
        policy: policy_arg(policy)?,
        channel: channel_arg(channel)?,
        workload: workload_arg(workload)?,
        forecast: forecast.map(workload_arg).transpose()?,
    };
    let key = read_key(record_key)?;
    let recording = match (log, resume, key) {
        (_, Some(path), key) => Recording::open_with_key(&path, key),
        (Some(path), None, key) => Recording::create_with_key(
            &path,
            Header::new(CODE_SESSION, "<python>", ".", seed, episodes),
            key,
        ),
        (None, None, None) => Ok(Recording::Off),
        (None, None, Some(key)) => Err(key_without_log(&key)),
    }
    .py_err()?;
    drive(py, exp, recording, events)
}

/// Writes a new random record key to `path` (which must not exist),
/// readable by its owner only, as `hil record keygen` does: give it as
/// `record_key` to `run`, `resume` or `run_session`, and keep it apart
/// from the logs it keys.
#[pyfunction]
pub(crate) fn record_keygen(path: PathBuf) -> PyResult<()> {
    RecordKey::generate(&path).map(drop).py_err()
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(record_keygen, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(resume, m)?)?;
    m.add_function(wrap_pyfunction!(run_session, m)?)?;
    Ok(())
}
