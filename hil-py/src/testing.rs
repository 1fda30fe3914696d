//! hil's conformance suites from Python (`hil.testing.check_*`), wrapping
//! `hil_conformance::check_*_with`: the same checks every Rust and
//! plugin implementation passes, run on Python components (or on hil's
//! own, built by a Python factory).
//!
//! A factory is called as for a registered type (see [`crate::registry`]):
//! `factory(actions=[...], dim=..., seed=...)` for policies and query
//! channels, `factory(seed=...)` for environments and workload models.

use hil_conformance::{
    CheckOptions, ConformanceFailure, ConformanceReport, check_environment_with, check_policy_with,
    check_query_channel_with, check_workload_model_with,
};
use hil_core::Result;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::components::{action_space, channel_arg, environment_arg, policy_arg, workload_arg};
use crate::errors::{ConformanceError, IntoPy, from_py_err};

/// The report as a dict: `subject`, `passed` (check names), `skipped`
/// (`[name, reason]` pairs).
fn report(py: Python<'_>, r: ConformanceReport) -> PyResult<Py<PyAny>> {
    let d = PyDict::new(py);
    d.set_item("subject", r.subject)?;
    let passed: Vec<&str> = r.passed.iter().map(|c| c.name()).collect();
    d.set_item("passed", passed)?;
    let skipped: Vec<(&str, String)> = r
        .skipped
        .into_iter()
        .map(|(c, why)| (c.name(), why))
        .collect();
    d.set_item("skipped", skipped)?;
    Ok(d.into_any().unbind())
}

/// A failure as `hil.ConformanceError` with `subject`, `check` (its name),
/// `detail` and `hint` (the likely cause and fix).
fn failure(py: Python<'_>, f: ConformanceFailure) -> PyErr {
    let err = ConformanceError::new_err(f.to_string());
    let v = err.value(py);
    let _ = v.setattr("kind", "Conformance");
    let _ = v.setattr("subject", &f.subject);
    let _ = v.setattr("check", f.check.name());
    let _ = v.setattr("detail", &f.detail);
    let _ = v.setattr("hint", f.hint());
    err
}

fn finish(
    py: Python<'_>,
    r: std::result::Result<ConformanceReport, ConformanceFailure>,
) -> PyResult<Py<PyAny>> {
    match r {
        Ok(r) => report(py, r),
        Err(f) => Err(failure(py, f)),
    }
}

/// The options over `actions` (a count or names, as for a policy) and
/// `dim`, unvalidated: the caller sets the rest, then validates once.
fn options(actions: &Bound<'_, PyAny>, dim: usize) -> PyResult<CheckOptions> {
    Ok(CheckOptions::default()
        .with_actions(action_space(actions)?)
        .with_context_dim(dim))
}

/// Calls `factory` with the build facts of `opts` and converts the result.
fn make<T>(
    factory: &Py<PyAny>,
    with_task: bool,
    opts: &CheckOptions,
    convert: impl Fn(&Bound<'_, PyAny>) -> PyResult<T>,
) -> Result<T> {
    Python::attach(|py| {
        let call = || -> PyResult<T> {
            let kw = PyDict::new(py);
            if with_task {
                kw.set_item("actions", opts.actions().names().to_vec())?;
                kw.set_item("dim", opts.context_dim())?;
            }
            kw.set_item("seed", 0)?;
            convert(&factory.bind(py).call((), Some(&kw))?)
        };
        call().map_err(|e| from_py_err(py, "python factory", "the factory", e))
    })
}

/// Runs hil's policy conformance suite on policies made by `factory`
/// (called as `factory(actions=[...], dim=..., seed=0)`; returns a Python
/// policy or a `hil.Policy`). Returns the report (`subject`, `passed`,
/// `skipped`); raises `ConformanceError` naming the failed `check` with
/// its `hint`.
#[pyfunction]
#[pyo3(signature = (factory, *, actions=None, dim=8))]
pub(crate) fn check_policy(
    py: Python<'_>,
    factory: Py<PyAny>,
    actions: Option<&Bound<'_, PyAny>>,
    dim: usize,
) -> PyResult<Py<PyAny>> {
    let opts = match actions {
        Some(a) => options(a, dim)?,
        None => options(&6usize.into_pyobject(py)?.into_any(), dim)?,
    };
    opts.validate().py_err()?;
    let r = py.detach(|| check_policy_with(&|| make(&factory, true, &opts, policy_arg), &opts));
    finish(py, r)
}

/// Runs hil's environment conformance suite on environments made by
/// `factory(seed=0)` (a Python environment or a `hil.Environment`), with at
/// most `attempts` attempts per item.
#[pyfunction]
#[pyo3(signature = (factory, *, attempts=3))]
pub(crate) fn check_environment(
    py: Python<'_>,
    factory: Py<PyAny>,
    attempts: u32,
) -> PyResult<Py<PyAny>> {
    let opts = CheckOptions::default().with_attempts(attempts);
    opts.validate().py_err()?;
    let r = py.detach(|| {
        check_environment_with(
            &|| make(&factory, false, &opts, |o| environment_arg(o).map(|e| e.0)),
            &opts,
        )
    });
    finish(py, r)
}

/// Runs hil's workload-model conformance suite on the model `factory(seed=0)`
/// makes (a Python model, a `hil.WorkloadModel`, or a bundled name).
#[pyfunction]
#[pyo3(signature = (factory,))]
pub(crate) fn check_workload_model(py: Python<'_>, factory: Py<PyAny>) -> PyResult<Py<PyAny>> {
    let opts = CheckOptions::default();
    let model = make(&factory, false, &opts, workload_arg).py_err()?;
    let r = py.detach(|| check_workload_model_with(model.as_ref(), &opts));
    finish(py, r)
}

/// Runs hil's query-channel conformance suite on channels made by
/// `factory(actions=[...], dim=..., seed=0)` (a Python channel or a
/// `hil.QueryChannel`).
#[pyfunction]
#[pyo3(signature = (factory, *, actions=None, dim=8, queries=36))]
pub(crate) fn check_query_channel(
    py: Python<'_>,
    factory: Py<PyAny>,
    actions: Option<&Bound<'_, PyAny>>,
    dim: usize,
    queries: usize,
) -> PyResult<Py<PyAny>> {
    let opts = match actions {
        Some(a) => options(a, dim)?,
        None => options(&6usize.into_pyobject(py)?.into_any(), dim)?,
    }
    .with_queries(queries);
    opts.validate().py_err()?;
    let r = py.detach(|| {
        check_query_channel_with(
            &|| make(&factory, true, &opts, |o| channel_arg(Some(o))),
            &opts,
        )
    });
    finish(py, r)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let sub = PyModule::new(m.py(), "testing")?;
    sub.add_function(wrap_pyfunction!(check_policy, &sub)?)?;
    sub.add_function(wrap_pyfunction!(check_environment, &sub)?)?;
    sub.add_function(wrap_pyfunction!(check_workload_model, &sub)?)?;
    sub.add_function(wrap_pyfunction!(check_query_channel, &sub)?)?;
    m.add_submodule(&sub)?;
    Ok(())
}
