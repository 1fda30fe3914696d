//! `hil.reproduce(...)`: the paper's simulated protocol, as `hil
//! reproduce` runs it (hil-experiments), returning the results as plain
//! Python data: the serde form of `hil_experiments::results::Reproduction`.

use std::path::PathBuf;
use std::time::Instant;

use hil_core::HilError;
use hil_core::plugin::ComponentKind;
use hil_experiments::output::{Timing, write_outputs};
use hil_experiments::{Method, Protocol, ProtocolSettings};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;

use crate::convert::{from_py, to_py};
use crate::errors::{IntoPy, to_py_err};

/// The protocol settings a `settings` argument names: None (the paper's,
/// or the quick preset with `quick`), a settings file path, or a dict whose
/// keys replace the preset's.
fn settings_of(settings: Option<&Bound<'_, PyAny>>, quick: bool) -> PyResult<ProtocolSettings> {
    let preset = if quick {
        ProtocolSettings::quick()
    } else {
        ProtocolSettings::paper()
    };
    let Some(s) = settings else {
        return Ok(preset);
    };
    if let Ok(d) = s.cast::<PyDict>() {
        let mut base = serde_json::to_value(&preset)
            .map_err(|e| HilError::serde("protocol settings", e))
            .py_err()?;
        let over: Value = from_py(d.as_any(), "protocol settings")?;
        if let (Some(b), Value::Object(o)) = (base.as_object_mut(), over) {
            b.extend(o);
        }
        let s: ProtocolSettings = serde_json::from_value(base)
            .map_err(|e| HilError::serde("protocol settings", e))
            .py_err()?;
        s.check_counts().py_err()?;
        return Ok(s);
    }
    let path: PathBuf = s.extract()?;
    ProtocolSettings::load(&path).py_err()
}

/// Registers the Python methods (`{"label": factory}` or `{"label":
/// (factory, params)}`) as policy types and appends them to the methods.
fn add_methods(settings: &mut ProtocolSettings, extra: &Bound<'_, PyDict>) -> PyResult<()> {
    for (label, spec) in extra.iter() {
        let label: String = label.extract()?;
        let (factory, params) = match spec.cast::<PyTuple>() {
            Ok(t) if t.len() == 2 => (t.get_item(0)?, Some(t.get_item(1)?)),
            _ => (spec.clone(), None),
        };
        let type_name = format!("python:{label}");
        crate::registry::register_factory(ComponentKind::Policy, &type_name, factory.unbind())
            .py_err()?;
        let mut table = match params {
            Some(p) => {
                match crate::convert::to_toml(&p, &format!("parameters of method `{label}`"))? {
                    toml::Value::Table(t) => t,
                    _ => {
                        return Err(to_py_err(HilError::invalid_input(
                            format!("extra_methods.{label}"),
                            "the parameters must be a dict",
                        )));
                    }
                }
            }
            None => toml::Table::new(),
        };
        table.insert("type".into(), toml::Value::String(type_name));
        if settings.methods.iter().any(|m| m.label == label) {
            return Err(to_py_err(HilError::invalid_parameter(
                "extra_methods",
                &label,
                "a method of that label exists already",
            )));
        }
        settings.methods.push(Method::new(&label, table));
    }
    Ok(())
}

/// Runs the paper's simulated protocol (every method, grid point, workload
/// model, seed and policy seed; hyperparameters chosen on validation) and
/// returns its results: the serde form of hil's `Reproduction`
/// (`paper_protocol`, `many_seeds`, `frontier`). The bundled data is
/// synthetic, calibrated to published figures: these are not the paper's
/// results.
///
/// `settings`: None (the paper's settings, or with `quick=True` the quick
/// preset), a settings TOML path, or a dict whose keys replace the
/// preset's. `extra_methods` adds methods written in Python:
/// `{"label": factory}` or `{"label": (factory, params)}`, where a factory
/// is called as `factory(actions=..., dim=..., seed=..., **params)` and
/// returns a policy (a Python object with the policy methods, or a
/// `hil.Policy`). `out` also writes the tables, figures and
/// results.json there (as `hil reproduce --out`); `records=True` adds every
/// run's record under `"records"`. Runs on rayon's pool
/// (`RAYON_NUM_THREADS`) with the GIL released.
#[pyfunction]
#[pyo3(signature = (settings=None, *, quick=false, seed=None, many_seeds=None, extra_methods=None, out=None, records=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reproduce(
    py: Python<'_>,
    settings: Option<&Bound<'_, PyAny>>,
    quick: bool,
    seed: Option<u64>,
    many_seeds: Option<usize>,
    extra_methods: Option<&Bound<'_, PyDict>>,
    out: Option<PathBuf>,
    records: bool,
) -> PyResult<Py<PyAny>> {
    let t0 = Instant::now();
    let mut s = settings_of(settings, quick)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    if let Some(n) = many_seeds {
        s.many_seeds = n;
    }
    if let Some(extra) = extra_methods {
        add_methods(&mut s, extra)?;
    }
    let (reproduction, runs) = py
        .detach(|| -> hil_core::Result<_> {
            let protocol = Protocol::from_settings(s)?;
            let setup_s = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let runs = protocol.run_all(&|_, _| {})?;
            let runs_s = t1.elapsed().as_secs_f64();
            let t2 = Instant::now();
            let reproduction = protocol.reproduction(&runs)?;
            if let Some(dir) = &out {
                let threads = rayon_threads();
                let mut timing = Timing {
                    setup_s,
                    runs_s,
                    report_s: 0.0,
                    threads,
                };
                timing.report_s = t2.elapsed().as_secs_f64();
                write_outputs(dir, &reproduction, &runs, &protocol.models, &timing)?;
            }
            Ok((reproduction, runs))
        })
        .py_err()?;
    let result = to_py(py, &reproduction, "reproduction")?;
    if records {
        result
            .bind(py)
            .set_item("records", to_py(py, &runs, "run records")?)?;
    }
    Ok(result)
}

/// The worker threads rayon's global pool uses.
fn rayon_threads() -> usize {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(reproduce, m)?)
}
