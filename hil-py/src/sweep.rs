//! Native support of `hil.sweep`: the paper's protocol and experiment
//! configs cut into independent jobs that any process can run, with
//! everything crossing as the Rust types' serde JSON (so a Ray worker and
//! the caller exchange plain strings, and Python never re-declares a
//! result shape).
//!
//! A job's result depends only on its key and the settings (every seed is
//! derived from them), so running the jobs in any order, in any process,
//! gives the records `Protocol::run_all` gives.

use std::path::Path;
use std::sync::{Arc, Mutex};

use hil_config::TaskContext;
use hil_core::HilError;
use hil_experiments::ExperimentConfig;
use hil_experiments::testbed::{RunKey, RunOutcome, RunRecord};
use hil_experiments::{Protocol, ProtocolSettings};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::reproduce::PythonComponents;

use crate::convert::{from_json, to_json};
use crate::errors::to_py_err;

/// A built protocol and its policies' build context.
struct Built {
    protocol: Protocol,
    ctx: TaskContext,
}

/// The protocol a process last built, by its settings' JSON and the
/// Python registry's generation (a re-registered Python component may be
/// another one under the same name): a worker that runs many jobs of one
/// sweep loads the dataset and models once.
static LAST: Mutex<Option<(String, u64, Arc<Built>)>> = Mutex::new(None);

fn built(settings_json: &str) -> PyResult<Arc<Built>> {
    let generation = crate::registry::generation();
    if let Ok(last) = LAST.lock()
        && let Some((json, g, b)) = last.as_ref()
        && json == settings_json
        && *g == generation
    {
        return Ok(b.clone());
    }
    let settings: ProtocolSettings = from_json("protocol settings", settings_json)?;
    let protocol = Protocol::from_settings(settings).map_err(to_py_err)?;
    let ctx = protocol.build_context().map_err(to_py_err)?;
    let b = Arc::new(Built { protocol, ctx });
    if let Ok(mut last) = LAST.lock() {
        *last = Some((settings_json.to_string(), generation, b.clone()));
    }
    Ok(b)
}

/// The settings of a named preset (`"paper"` or `"quick"`) as JSON.
#[pyfunction]
fn protocol_preset_json(name: &str) -> PyResult<String> {
    let settings = match name {
        "paper" => ProtocolSettings::paper(),
        "quick" => ProtocolSettings::quick(),
        other => {
            return Err(to_py_err(HilError::invalid_parameter(
                "preset",
                other,
                "known presets are `paper` and `quick`",
            )));
        }
    };
    to_json("protocol settings", &settings)
}

/// Protocol settings read from a TOML file (errors name file, line and
/// field), as JSON.
#[pyfunction]
fn protocol_settings_from_file(py: Python<'_>, path: &str) -> PyResult<String> {
    let settings = py
        .detach(|| ProtocolSettings::load(Path::new(path)))
        .map_err(to_py_err)?;
    to_json("protocol settings", &settings)
}

/// Every job of the protocol (its `RunKey`s, as one JSON array), after
/// checking the settings against the dataset and models they name.
#[pyfunction]
fn protocol_jobs_json(py: Python<'_>, settings_json: &str) -> PyResult<String> {
    let b = py.detach(|| built(settings_json))?;
    let jobs = b.protocol.jobs().map_err(to_py_err)?;
    to_json("protocol jobs", &jobs)
}

/// Runs the jobs `keys_json` (a JSON array of `RunKey`s) one after the
/// other and returns their `RunRecord`s as a JSON array, in order. The GIL
/// is released while they run.
#[pyfunction]
fn protocol_run_json(py: Python<'_>, settings_json: &str, keys_json: &str) -> PyResult<String> {
    let keys: Vec<RunKey> = from_json("protocol jobs", keys_json)?;
    let records = py.detach(|| -> PyResult<Vec<RunRecord>> {
        let b = built(settings_json)?;
        keys.iter()
            .map(|k| b.protocol.run_one(k, &b.ctx).map_err(to_py_err))
            .collect()
    })?;
    to_json("run records", &records)
}

/// Runs every job in this process with all its cores
/// (`Protocol::run_until_cancelled`), returning the records as a JSON array
/// in job order. Ctrl-C stops it (`KeyboardInterrupt`); `progress` is None,
/// a callable `progress(done, total)` or `True` (a line on stderr).
#[pyfunction]
#[pyo3(signature = (settings_json, progress = None))]
fn protocol_run_all_json(
    py: Python<'_>,
    settings_json: &str,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<String> {
    let outcome = crate::interrupt::run(py, progress, "hil.sweep", |control| {
        let b = built(settings_json)?;
        b.protocol
            .run_until_cancelled(&|done, total| control.report(done, total), &control.cancel)
            .map_err(to_py_err)
    })?;
    match outcome? {
        RunOutcome::Finished(records) => to_json("run records", &records),
        RunOutcome::Cancelled { done, total } => Err(crate::reproduce::cancelled((done, total))),
    }
}

/// A registration as Python sees it: `(kind, type name, factory)`, the
/// arguments of `hil.register`.
type RegistrationTuple = (&'static str, String, Py<PyAny>);

/// The settings `settings_json` with the Python components added (as
/// `hil.reproduce` takes them), and the registrations a Ray worker must
/// repeat before running jobs: `(settings_json, [(kind, name, factory)])`.
#[pyfunction]
#[pyo3(signature = (settings_json, *, extra_methods = None, channel = None, environment = None, workload_models = None))]
fn protocol_with_components(
    settings_json: &str,
    extra_methods: Option<&Bound<'_, PyDict>>,
    channel: Option<&Bound<'_, PyAny>>,
    environment: Option<&Bound<'_, PyAny>>,
    workload_models: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, Vec<RegistrationTuple>)> {
    let mut settings: ProtocolSettings = from_json("protocol settings", settings_json)?;
    let regs = PythonComponents {
        extra_methods,
        channel,
        environment,
        workload_models,
    }
    .add_to(&mut settings)?;
    let regs = regs
        .into_iter()
        .map(|r| (crate::registry::kind_name(r.kind), r.name, r.factory))
        .collect();
    Ok((to_json("protocol settings", &settings)?, regs))
}

/// The protocol's selection, aggregation and frontier of `records_json`
/// (`Protocol::reproduction`), as JSON.
#[pyfunction]
fn protocol_reproduction_json(
    py: Python<'_>,
    settings_json: &str,
    records_json: &str,
) -> PyResult<String> {
    let records: Vec<RunRecord> = from_json("run records", records_json)?;
    let reproduction = py.detach(|| {
        let b = built(settings_json)?;
        b.protocol.reproduction(&records).map_err(to_py_err)
    })?;
    to_json("reproduction", &reproduction)
}

/// Runs the experiment config `config_toml` (named `name` in errors;
/// relative paths resolve against `base_dir`) with its master seed replaced
/// by `seed`, returning its `ExperimentSummary` as JSON.
#[pyfunction]
#[pyo3(signature = (config_toml, seed, name = "experiment.toml", base_dir = "."))]
fn experiment_run_json(
    py: Python<'_>,
    config_toml: &str,
    seed: u64,
    name: &str,
    base_dir: &str,
) -> PyResult<String> {
    let summary = py
        .detach(|| -> hil_core::Result<_> {
            let mut config = ExperimentConfig::parse(config_toml, Path::new(name))?;
            config.seed = seed;
            config.build(Path::new(base_dir))?.run(&mut [], |_, _| {})
        })
        .map_err(to_py_err)?;
    to_json("experiment summary", &summary)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(protocol_preset_json, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_settings_from_file, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_jobs_json, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_run_json, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_run_all_json, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_with_components, m)?)?;
    m.add_function(wrap_pyfunction!(protocol_reproduction_json, m)?)?;
    m.add_function(wrap_pyfunction!(experiment_run_json, m)?)?;
    Ok(())
}
