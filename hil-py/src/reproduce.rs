//! `hil.reproduce(...)`: the paper's simulated protocol, as `hil
//! reproduce` runs it (hil-experiments), returning the results as plain
//! Python data: the serde form of `hil_experiments::results::Reproduction`.

use std::path::PathBuf;
use std::time::Instant;

use hil_core::HilError;
use hil_experiments::output::{Timing, report};
use hil_experiments::testbed::{ModelSource, RunOutcome};
use hil_experiments::{Method, Protocol, ProtocolSettings};
use hil_plugin::ComponentKind;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;

use crate::convert::{from_py, to_py};
use crate::errors::{IntoPy, to_py_err};

/// The protocol settings a `settings` argument names: None (the paper's,
/// or the quick preset with `quick`), a settings file path, or a dict whose
/// keys replace the preset's (a dict that replaces `methods` drops the
/// preset's `grid_variants` unless it gives its own).
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
            // The preset's grid variants retune the preset's methods by
            // label: a dict that replaces the methods and names no variants
            // of its own runs its methods' own grids only.
            if o.contains_key("methods") && !o.contains_key("grid_variants") {
                b.remove("grid_variants");
            }
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

/// A Python factory registered as a hil component type for a protocol
/// run; a Ray worker registers it again before running jobs.
pub(crate) struct Registration {
    pub(crate) kind: ComponentKind,
    pub(crate) name: String,
    pub(crate) factory: Py<PyAny>,
}

/// The Python components a protocol run is given (`hil.reproduce`'s and
/// `hil.sweep`'s keyword arguments of these names).
#[derive(Default)]
pub(crate) struct PythonComponents<'a, 'py> {
    pub(crate) extra_methods: Option<&'a Bound<'py, PyDict>>,
    pub(crate) channel: Option<&'a Bound<'py, PyAny>>,
    pub(crate) environment: Option<&'a Bound<'py, PyAny>>,
    pub(crate) workload_models: Option<&'a Bound<'py, PyDict>>,
}

impl PythonComponents<'_, '_> {
    /// Registers every Python factory as a component type and names it in
    /// `settings` (methods appended, the channel and environment set,
    /// workload models appended), so the one protocol path runs them.
    pub(crate) fn add_to(&self, settings: &mut ProtocolSettings) -> PyResult<Vec<Registration>> {
        let mut regs = Vec::new();
        if let Some(extra) = self.extra_methods {
            for (label, spec) in extra.iter() {
                let label: String = label.extract()?;
                if settings.methods.iter().any(|m| m.label == label) {
                    return Err(to_py_err(HilError::invalid_parameter(
                        "extra_methods",
                        &label,
                        "a method of that label exists already",
                    )));
                }
                let what = format!("extra_methods.{label}");
                let mut table =
                    component_table(&spec, ComponentKind::Policy, &label, &what, None, &mut regs)?;
                // Every method of a protocol is pretrained alike (the
                // built-in ones by the paper's table): a Python factory
                // too, unless its parameters say `pretrain = false`.
                if spec.cast::<PyDict>().is_err() {
                    table
                        .entry(crate::pretrain::KEY)
                        .or_insert(toml::Value::Boolean(true));
                }
                settings.methods.push(Method::new(&label, table));
            }
        }
        if let Some(c) = self.channel {
            let name = python_name(c);
            let table = component_table(
                c,
                ComponentKind::QueryChannel,
                &name,
                "channel",
                None,
                &mut regs,
            )?;
            settings.channel = Some(table);
        }
        if let Some(e) = self.environment {
            let name = python_name(e);
            let table = component_table(
                e,
                ComponentKind::Environment,
                &name,
                "environment",
                None,
                &mut regs,
            )?;
            settings.environment = Some(table);
        }
        if let Some(models) = self.workload_models {
            for (name, spec) in models.iter() {
                let name: String = name.extract()?;
                if settings.models.iter().any(|m| m.name == name) {
                    return Err(to_py_err(HilError::invalid_parameter(
                        "workload_models",
                        &name,
                        "a workload model of that name exists already",
                    )));
                }
                let what = format!("workload_models.{name}");
                let table = component_table(
                    &spec,
                    ComponentKind::WorkloadModel,
                    &name,
                    &what,
                    Some("predict"),
                    &mut regs,
                )?;
                settings.models.push(ModelSource::configured(&name, table));
            }
        }
        Ok(regs)
    }
}

/// A factory that returns one object whatever it is called with (a
/// workload model shared by every run); it pickles as that object, so a
/// Ray worker can get it.
#[pyclass(module = "hil._hil", name = "_Constant", frozen)]
struct Constant {
    object: Py<PyAny>,
}

#[pymethods]
impl Constant {
    #[new]
    fn new(object: Py<PyAny>) -> Self {
        Self { object }
    }

    #[pyo3(signature = (*_args, **_kwargs))]
    fn __call__(
        &self,
        py: Python<'_>,
        _args: &Bound<'_, PyTuple>,
        _kwargs: Option<&Bound<'_, PyDict>>,
    ) -> Py<PyAny> {
        self.object.clone_ref(py)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, pyo3::types::PyType>, (Py<PyAny>,)) {
        (slf.get_type(), (slf.get().object.clone_ref(slf.py()),))
    }
}

/// A Python factory's name: its `__name__` (a class or function), else
/// its type's.
fn python_name(obj: &Bound<'_, PyAny>) -> String {
    obj.getattr("__name__")
        .and_then(|n| n.extract::<String>())
        .or_else(|_| obj.get_type().name().and_then(|n| n.extract::<String>()))
        .unwrap_or_else(|_| "component".into())
}

/// The component table of one argument: a dict is a table naming a
/// built-in, plugin or registered type (`{"type": "simulated_expert",
/// ...}`); a factory, or a `(factory, params)` tuple, is registered as the
/// type `python:<name>` of `kind`. With `instance_method`, an object that
/// has that method (and is not a class) is itself the component: every
/// build returns it.
fn component_table(
    spec: &Bound<'_, PyAny>,
    kind: ComponentKind,
    name: &str,
    what: &str,
    instance_method: Option<&str>,
    regs: &mut Vec<Registration>,
) -> PyResult<toml::Table> {
    let py = spec.py();
    let as_table = |v: &Bound<'_, PyAny>| -> PyResult<toml::Table> {
        match crate::convert::to_toml(v, what)? {
            toml::Value::Table(t) => Ok(t),
            _ => Err(to_py_err(HilError::invalid_input(
                what,
                "the parameters must be a dict",
            ))),
        }
    };
    if spec.cast::<PyDict>().is_ok() {
        return as_table(spec);
    }
    let (factory, params) = match spec.cast::<PyTuple>() {
        Ok(t) if t.len() == 2 => (t.get_item(0)?, Some(t.get_item(1)?)),
        _ => (spec.clone(), None),
    };
    let is_instance = instance_method.is_some_and(|m| {
        !factory.is_instance_of::<pyo3::types::PyType>() && factory.hasattr(m).unwrap_or(false)
    });
    let factory = if is_instance {
        Bound::new(
            py,
            Constant {
                object: factory.clone().unbind(),
            },
        )?
        .into_any()
    } else if factory.is_callable() {
        factory
    } else {
        return Err(to_py_err(HilError::invalid_input(
            what,
            "give a factory (a class or function), a (factory, params) tuple, or a dict \
             naming a registered type",
        )));
    };
    let type_name = format!("python:{name}");
    crate::registry::register_factory(kind, &type_name, factory.clone().unbind()).py_err()?;
    regs.push(Registration {
        kind,
        name: type_name.clone(),
        factory: factory.unbind(),
    });
    let mut table = match params {
        Some(p) => as_table(&p)?,
        None => toml::Table::new(),
    };
    table.insert("type".into(), toml::Value::String(type_name));
    Ok(table)
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
/// preset's.
///
/// Python components join the protocol (each Python factory is registered
/// as the hil type `python:<name>`; an exception inside one becomes a
/// `hil.BackendError` naming it):
///
/// - `extra_methods`: `{"label": factory}` or `{"label": (factory,
///   params)}`; a factory is called as `factory(actions=..., dim=...,
///   seed=..., **params)` and returns a policy (a Python object with the
///   policy methods, or a `hil.Policy`).
/// - `channel`: what answers queries instead of the perfect expert: a
///   factory called per episode as `factory(actions=..., dim=..., seed=...,
///   **params)` returning a query channel (an object with `ask(query)`), a
///   `(factory, params)` tuple, or a dict naming a registered type
///   (`{"type": "simulated_expert", "error_rate": 0.2}`).
/// - `environment`: what presents the items instead of the dataset replay:
///   a factory called per episode as `factory(foods=[...],
///   items_per_episode=..., seed=..., **params)` (plus `dataset=` when the
///   settings name a dataset directory) returning an environment with the
///   dataset's actions and context dimension, a `(factory, params)` tuple,
///   or a dict naming a registered type (`{"type": "food_replay"}`).
/// - `workload_models`: `{"name": model}` added to the settings' models: a
///   model object (with `predict`; shared by every run, so it must be
///   stateless), a factory called as `factory(seed=..., **params)`, a
///   `(factory, params)` tuple, or a dict naming a registered type.
///
/// `out` also writes the tables, figures and results.json there (as `hil
/// reproduce --out`); `records=True` adds every run's record under
/// `"records"`. Runs on the default `hil_jobs::Runner` (`RAYON_NUM_THREADS`,
/// else one worker per core) with the GIL released; Ctrl-C stops it within
/// about one episode per thread (`KeyboardInterrupt`). `progress`: a callable `progress(done, total)`
/// called on this thread as runs finish, or `True` for a line on stderr.
#[pyfunction]
#[pyo3(signature = (settings=None, *, quick=false, seed=None, many_seeds=None, extra_methods=None, channel=None, environment=None, workload_models=None, out=None, records=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reproduce(
    py: Python<'_>,
    settings: Option<&Bound<'_, PyAny>>,
    quick: bool,
    seed: Option<u64>,
    many_seeds: Option<usize>,
    extra_methods: Option<&Bound<'_, PyDict>>,
    channel: Option<&Bound<'_, PyAny>>,
    environment: Option<&Bound<'_, PyAny>>,
    workload_models: Option<&Bound<'_, PyDict>>,
    out: Option<PathBuf>,
    records: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let t0 = Instant::now();
    let mut s = settings_of(settings, quick)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    if let Some(n) = many_seeds {
        s.many_seeds = n;
    }
    PythonComponents {
        extra_methods,
        channel,
        environment,
        workload_models,
    }
    .add_to(&mut s)?;
    let ran = crate::interrupt::run(py, progress, "hil.reproduce", |control| {
        let protocol = Protocol::from_settings(s)?;
        let setup_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let runs = match protocol
            .run_until_cancelled(&|done, total| control.report(done, total), &control.cancel)?
        {
            RunOutcome::Finished(runs) => runs,
            RunOutcome::Cancelled { done, total } => return Ok(Err((done, total))),
        };
        let mut timing = Timing {
            setup_s,
            runs_s: t1.elapsed().as_secs_f64(),
            report_s: 0.0,
            threads: protocol.runner.threads(),
        };
        let (reproduction, _) = report(&protocol, &runs, out.as_deref(), &mut timing)?;
        hil_core::Result::Ok(Ok((reproduction, runs)))
    })?;
    let (reproduction, runs) = ran.py_err()?.map_err(cancelled)?;
    let result = to_py(py, &reproduction, "reproduction")?;
    if records {
        result
            .bind(py)
            .set_item("records", to_py(py, &runs, "run records")?)?;
    }
    Ok(result)
}

/// A run that stopped with no Python exception to raise (only a cancel flag
/// raised by hand does that).
pub(crate) fn cancelled((done, total): (usize, usize)) -> PyErr {
    pyo3::exceptions::PyKeyboardInterrupt::new_err(format!(
        "the protocol was cancelled after {done} of {total} runs"
    ))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Constant>()?;
    m.add_function(wrap_pyfunction!(reproduce, m)?)
}
