//! Python factories as named hil component types: once registered, a name
//! works wherever a built-in type name does (experiment configs, protocol
//! methods, `hil.Policy(name, ...)`), through hil-core's static plugin
//! registry.
//!
//! A factory is called with keyword arguments: `actions` (list of action
//! names), `dim` and `seed` for policies and query channels; `seed` for
//! environments and workload models; plus the component's parameters from
//! its config table. A Python class whose constructor takes those is a
//! factory.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::{Arc, Mutex};

use hil_config::{BuildContext, TaskContext};
use hil_core::{HilError, Result};
use hil_plugin::ComponentKind;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

use crate::components::{channel_arg, environment_arg, policy_arg, workload_arg};
use crate::convert::to_py;
use crate::errors::{IntoPy, from_py_err};

/// The current Python factory of every registered (kind, name).
static FACTORIES: Mutex<Vec<(ComponentKind, String, Py<PyAny>)>> = Mutex::new(Vec::new());
/// The (kind, name) pairs registered with hil-core (once each: a second
/// registration of a name only replaces its Python factory).
static REGISTERED: Mutex<Option<HashSet<(ComponentKind, String)>>> = Mutex::new(None);

fn factory(kind: ComponentKind, name: &str) -> Result<Py<PyAny>> {
    Python::attach(|py| {
        let all = FACTORIES.lock().unwrap_or_else(|e| e.into_inner());
        all.iter()
            .find(|(k, n, _)| *k == kind && n == name)
            .map(|(_, _, f)| f.clone_ref(py))
    })
    .ok_or_else(|| HilError::state("python registry", format!("no {kind} `{name}`")))
}

/// Calls the Python factory of (`kind`, `name`) with `params` (a table,
/// parsed) and the build facts as keyword arguments, then converts what it
/// returns.
fn build<T>(
    kind: ComponentKind,
    name: &str,
    params: Value,
    facts: impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()>,
    convert: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>,
) -> Result<T> {
    let f = factory(kind, name)?;
    let label = format!("python {kind} factory `{name}`");
    Python::attach(|py| {
        let call = || -> PyResult<T> {
            let kwargs = PyDict::new(py);
            if let Ok(obj) = to_py(py, &params, "parameters")?.bind(py).cast::<PyDict>() {
                kwargs.update(obj.as_mapping())?;
            }
            facts(&kwargs)?;
            let made = f.bind(py).call((), Some(&kwargs))?;
            convert(&made)
        };
        call().map_err(|e| from_py_err(py, &label, "the factory", e))
    })
}

fn task_facts(ctx: &TaskContext) -> impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()> + '_ {
    move |kw| {
        kw.set_item("actions", ctx.action_space().names().to_vec())?;
        kw.set_item("dim", ctx.context_dim())?;
        kw.set_item("seed", ctx.base().seed)
    }
}

fn base_facts(ctx: &BuildContext) -> impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()> + '_ {
    move |kw| kw.set_item("seed", ctx.seed)
}

/// Bumped by every registration, so a cache of built components (the
/// sweep's protocol) can tell when a name's factory may have changed.
static GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// How many registrations this process has made.
pub(crate) fn generation() -> u64 {
    GENERATION.load(std::sync::atomic::Ordering::SeqCst)
}

/// Registers `factory` as the hil component type `name` of `kind`.
pub(crate) fn register_factory(kind: ComponentKind, name: &str, factory: Py<PyAny>) -> Result<()> {
    GENERATION.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    {
        let mut all = FACTORIES.lock().unwrap_or_else(|e| e.into_inner());
        all.retain(|(k, n, _)| !(*k == kind && n == name));
        all.push((kind, name.to_string(), factory));
    }
    let mut registered = REGISTERED.lock().unwrap_or_else(|e| e.into_inner());
    let set = registered.get_or_insert_with(HashSet::new);
    if set.contains(&(kind, name.to_string())) {
        return Ok(());
    }
    let label = format!("<python {kind} {name}>");
    let n = name.to_string();
    let desc = "a Python component (hil-py)";
    hil_plugin::register_static(Path::new(&label), |r| match kind {
        ComponentKind::Policy => r.policy(name, desc, move |p, ctx| {
            let (params, pretrain) = crate::pretrain::take_flag(p.parse(&n)?)?;
            build(kind, &n, params, task_facts(ctx), |o| {
                if pretrain {
                    crate::pretrain::pretrain(o, ctx)?;
                }
                policy_arg(o)
            })
        }),
        ComponentKind::QueryChannel => r.query_channel(name, desc, move |p, ctx| {
            build(kind, &n, p.parse(&n)?, task_facts(ctx), |o| {
                channel_arg(Some(o))
            })
        }),
        ComponentKind::Environment => r.environment(name, desc, move |p, ctx| {
            build(kind, &n, p.parse(&n)?, base_facts(ctx), |o| {
                environment_arg(o).map(|e| e.0)
            })
        }),
        ComponentKind::WorkloadModel => r.workload_model(name, desc, move |p, ctx| {
            let m: Arc<dyn hil_core::WorkloadModel> =
                build(kind, &n, p.parse(&n)?, base_facts(ctx), workload_arg)?;
            Ok(Box::new(ArcWorkload(m)))
        }),
    })?;
    set.insert((kind, name.to_string()));
    Ok(())
}

/// A shared workload model as the box a factory returns.
struct ArcWorkload(Arc<dyn hil_core::WorkloadModel>);

impl hil_core::WorkloadModel for ArcWorkload {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn predict(&self, input: &hil_core::WorkloadInput<'_>) -> Result<f64> {
        self.0.predict(input)
    }
    fn predict_if_queried(
        &self,
        input: &hil_core::WorkloadInput<'_>,
        kind: hil_core::QueryKind,
    ) -> Result<f64> {
        self.0.predict_if_queried(input, kind)
    }
}

/// The names `register` takes for the four kinds.
const KINDS: [(&str, ComponentKind); 4] = [
    ("policy", ComponentKind::Policy),
    ("environment", ComponentKind::Environment),
    ("workload_model", ComponentKind::WorkloadModel),
    ("query_channel", ComponentKind::QueryChannel),
];

/// The name `register` takes for `kind`.
pub(crate) fn kind_name(kind: ComponentKind) -> &'static str {
    KINDS
        .iter()
        .find(|(_, k)| *k == kind)
        .map_or("policy", |(n, _)| n)
}

fn kind_of(kind: &str) -> Result<ComponentKind> {
    let kinds: HashMap<&str, ComponentKind> = KINDS.into();
    kinds.get(kind).copied().ok_or_else(|| {
        HilError::invalid_parameter(
            "kind",
            kind,
            "must be `policy`, `environment`, `workload_model` or `query_channel`",
        )
    })
}

/// Registers a Python factory (e.g. a class) as the hil component type
/// `name` of `kind` (`policy`, `environment`, `workload_model` or
/// `query_channel`), usable wherever a built-in type name is: in
/// experiment configs (`type = "name"`), protocol methods and the
/// component constructors. Registering a name again replaces its factory.
#[pyfunction]
#[pyo3(signature = (kind, name, factory))]
pub(crate) fn register(kind: &str, name: &str, factory: Py<PyAny>) -> PyResult<()> {
    register_factory(kind_of(kind).py_err()?, name, factory).py_err()
}

pub(crate) fn register_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(register, m)?)
}
