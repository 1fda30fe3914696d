//! Python objects serving as hil components: Rust wrappers that hold the
//! Python object and call it with the GIL, so a Python class with the right
//! methods is a [`Policy`], [`WorkloadModel`], [`QueryChannel`] or
//! [`Environment`] in hil's session loop, the paper's protocol and the
//! conformance suites.
//!
//! A Python exception inside a call becomes a [`HilError::Backend`] naming
//! the component (``python policy `MyPolicy` ``) and the call, with the
//! Python exception kept as its source (see [`crate::errors::from_py_err`]);
//! it never unwinds into hil.
//!
//! The methods each kind must have are documented on the Python side
//! (`hil-py/README.md`, "Python components inside hil", and `_hil.pyi`).

use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Decision, DecisionInput, Environment, Feedback,
    HilError, Item, Outcome, Policy, Query, QueryChannel, QueryKind, Response, Result,
    WorkloadInput, WorkloadModel,
};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

use crate::convert::{from_py, to_py};
use crate::errors::from_py_err;

/// A Python object and the name hil's errors give it.
#[derive(Debug)]
struct Held {
    object: Py<PyAny>,
    label: String,
}

impl Held {
    fn new(py: Python<'_>, object: Py<PyAny>, kind: &str) -> Self {
        let name = name_of(object.bind(py));
        Self {
            object,
            label: format!("python {kind} `{name}`"),
        }
    }

    /// Runs `f` on the object with the GIL held; a Python exception
    /// becomes a hil error naming the component and `call`.
    fn call<T>(&self, call: &str, f: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>) -> Result<T> {
        Python::attach(|py| {
            f(self.object.bind(py)).map_err(|e| from_py_err(py, &self.label, call, e))
        })
    }

    fn has(&self, method: &str) -> bool {
        Python::attach(|py| self.object.bind(py).hasattr(method).unwrap_or(false))
    }
}

/// The component's `name` attribute, or its class name.
fn name_of(object: &Bound<'_, PyAny>) -> String {
    object
        .getattr("name")
        .and_then(|n| n.extract::<String>())
        .or_else(|_| object.get_type().name().and_then(|n| n.extract::<String>()))
        .unwrap_or_else(|_| "python".into())
}

/// An integer attribute (or zero-argument method) the component must have.
fn required_usize(object: &Bound<'_, PyAny>, attr: &str, label: &str) -> PyResult<usize> {
    let v = object.getattr(attr).map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{label} has no `{attr}`: a Python component must say it (see hil's README)"
        ))
    })?;
    let v = if v.is_callable() { v.call0()? } else { v };
    v.extract()
}

/// A Python object as a hil [`Policy`].
///
/// Calls `decide(context, info)` (returns an arm index, or a dict in the
/// serde form of a `Decision` or a `Choice`), `observe(context, arm,
/// reward, info)`, and optionally `seed(seed)`, `save()` (JSON-able
/// state) and `restore(state)`. `n_arms` and `dim` are read once.
#[derive(Debug)]
pub(crate) struct PyPolicy {
    held: Held,
    name: String,
    n_arms: usize,
    dim: usize,
}

impl PyPolicy {
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>) -> PyResult<Self> {
        let held = Held::new(py, object, "policy");
        let bound = held.object.bind(py);
        let n_arms = required_usize(bound, "n_arms", &held.label)?;
        let dim = required_usize(bound, "dim", &held.label)?;
        let name = name_of(bound);
        Ok(Self {
            held,
            name,
            n_arms,
            dim,
        })
    }
}

/// What a Python policy's `decide` may return, for the errors that say so.
const DECISION_FORMS: &str = "a Python policy's decide must return an arm index (an int in \
     0..n_arms), a choice (hil.Act(arm), hil.Query(fallback, kind=...)) or a decision dict \
     ({\"choice\": ..., \"diagnostics\": ...}); see hil-py/README.md";

/// The decision a Python policy returned: an arm index, a `Choice` dict
/// (`{"type": "act", "arm": 2}`) or a `Decision` dict, read without JSON
/// text so that NaN or infinite diagnostics reach the checks that name
/// them. An index of the wrong type is a `TypeError`, a negative one a
/// `ValueError`; an arm out of range is left to the checks every policy
/// meets (the session's `ArmOutOfRange`, the suite's `arm in range`).
fn decision_from(value: &Bound<'_, PyAny>) -> PyResult<Decision> {
    use pyo3::exceptions::{PyTypeError, PyValueError};
    use pyo3::types::{PyBool, PyDict};
    let got = || -> PyResult<String> {
        Ok(format!(
            "got {} {}",
            value.get_type().name()?,
            value.repr()?
        ))
    };
    // An int, or a NumPy integer (both have `__index__`); a bool is not an arm.
    let is_index = !value.is_instance_of::<PyBool>() && value.hasattr("__index__")?;
    Ok(if is_index {
        match value.extract::<usize>() {
            Ok(arm) => Decision::act(ArmId(arm)),
            Err(_) => {
                return Err(PyValueError::new_err(format!(
                    "{DECISION_FORMS}; {}",
                    got()?
                )));
            }
        }
    } else if let Ok(d) = value.cast::<PyDict>() {
        if d.contains("choice")? {
            crate::convert::from_py_data(value, "the decision a Python policy returned")?
        } else {
            Decision {
                choice: crate::convert::from_py_data(value, "the choice a Python policy returned")?,
                diagnostics: Default::default(),
            }
        }
    } else {
        return Err(PyTypeError::new_err(format!(
            "{DECISION_FORMS}; {}",
            got()?
        )));
    })
}

/// What a Python policy's `decide` receives besides the context.
fn decision_info<'py>(py: Python<'py>, input: &DecisionInput<'_>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t", input.t)?;
    d.set_item("item_index", input.item_index)?;
    d.set_item("items_seen", input.items_seen)?;
    d.set_item("attempt", input.attempt)?;
    d.set_item("wl0", input.workload.wl0())?;
    d.set_item("n_queries", input.workload.history().len())?;
    // Forecasts where a model is configured (None otherwise).
    d.set_item("workload_now", input.workload.now().ok())?;
    d.set_item(
        "workload_if_queried",
        input.workload.if_queried(QueryKind::default()).ok(),
    )?;
    Ok(d)
}

impl PyPolicy {
    /// The error of `save` or `restore` on a policy without both methods.
    fn cannot_checkpoint(&self, operation: &str) -> HilError {
        HilError::unsupported(
            &self.held.label,
            operation,
            "it has no save() and restore() methods (give both to checkpoint its state)",
        )
    }
}

/// The [`Policy`] methods of a wrapper that keeps the facts (`name`,
/// `n_arms`, `dim`) of the policy it wraps, read once.
macro_rules! policy_facts {
    () => {
        fn name(&self) -> &str {
            &self.name
        }
        fn n_arms(&self) -> usize {
            self.n_arms
        }
        fn dim(&self) -> usize {
            self.dim
        }
    };
}
pub(crate) use policy_facts;

impl Policy for PyPolicy {
    policy_facts!();

    fn seed(&mut self, seed: u64) {
        if self.held.has("seed") {
            // `seed` cannot fail in the trait; a failing Python `seed`
            // surfaces at the next call that can (it keeps its old seed).
            let _ = self
                .held
                .call("seed", |o| o.call_method1("seed", (seed,)).map(drop));
        }
    }

    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        hil_core::policy::check_input(self, input)?;
        self.held.call("decide", |o| {
            let py = o.py();
            let x = PyArray1::from_slice(py, input.context.as_slice());
            let out = o.call_method1("decide", (x, decision_info(py, input)?))?;
            decision_from(&out)
        })
    }

    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        hil_core::policy::check_feedback(self, feedback)?;
        self.held.call("observe", |o| {
            let py = o.py();
            let x = PyArray1::from_slice(py, feedback.context.as_slice());
            let info = PyDict::new(py);
            info.set_item("t", feedback.t)?;
            info.set_item("from_expert", feedback.from_expert)?;
            o.call_method1("observe", (x, feedback.arm.0, feedback.reward, info))?;
            Ok(())
        })
    }

    fn save(&self) -> Result<Value> {
        // Without both methods there is no checkpoint: what the trait's
        // default says (and the conformance suite skips).
        if !(self.held.has("save") && self.held.has("restore")) {
            return Err(self.cannot_checkpoint("save"));
        }
        self.held.call("save", |o| {
            crate::convert::to_value(&o.call_method0("save")?, "state")
        })
    }

    fn restore(&mut self, state: Value) -> Result<()> {
        if !(self.held.has("save") && self.held.has("restore")) {
            return Err(self.cannot_checkpoint("restore"));
        }
        self.held.call("restore", |o| {
            o.call_method1("restore", (to_py(o.py(), &state, "policy state")?,))?;
            Ok(())
        })
    }
}

/// A Python object as a hil [`WorkloadModel`]: `predict(wl0, query_times,
/// t)` returns WL_t, where `query_times` is a 1-d int array of the times
/// of the queries asked so far; optional `predict_if_queried(wl0,
/// query_times, t)` (else the trait's default).
#[derive(Debug)]
pub(crate) struct PyWorkload {
    held: Held,
    name: String,
}

impl PyWorkload {
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>) -> Self {
        let held = Held::new(py, object, "workload model");
        let name = name_of(held.object.bind(py));
        Self { held, name }
    }
}

fn query_times<'py>(py: Python<'py>, input: &WorkloadInput<'_>) -> Bound<'py, PyArray1<u64>> {
    let times: Vec<u64> = input.history.records().iter().map(|r| r.t).collect();
    PyArray1::from_vec(py, times)
}

impl WorkloadModel for PyWorkload {
    fn name(&self) -> &str {
        &self.name
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        self.held.call("predict", |o| {
            o.call_method1("predict", (input.wl0, query_times(o.py(), input), input.t))?
                .extract()
        })
    }

    fn predict_if_queried(&self, input: &WorkloadInput<'_>, kind: QueryKind) -> Result<f64> {
        if !self.held.has("predict_if_queried") {
            let mut h = input.history.clone();
            h.push(input.t, kind)?;
            return self.predict(&input.with_history(&h));
        }
        self.held.call("predict_if_queried", |o| {
            o.call_method1(
                "predict_if_queried",
                (input.wl0, query_times(o.py(), input), input.t),
            )?
            .extract()
        })
    }
}

/// A Python object as a hil [`QueryChannel`]: `ask(query)` gets the
/// query's serde form as a dict and returns an arm index or a `Response`
/// dict; optional `seed(seed)`.
#[derive(Debug)]
pub(crate) struct PyChannel {
    held: Held,
    name: String,
}

impl PyChannel {
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>) -> Self {
        let held = Held::new(py, object, "query channel");
        let name = name_of(held.object.bind(py));
        Self { held, name }
    }
}

impl QueryChannel for PyChannel {
    fn name(&self) -> &str {
        &self.name
    }

    fn seed(&mut self, seed: u64) {
        if self.held.has("seed") {
            let _ = self
                .held
                .call("seed", |o| o.call_method1("seed", (seed,)).map(drop));
        }
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        self.held.call("ask", |o| {
            let out = o.call_method1("ask", (to_py(o.py(), query, "query")?,))?;
            if let Ok(arm) = out.extract::<usize>() {
                return Ok(Response::action(ArmId(arm)));
            }
            from_py(&out, "the response a Python channel returned")
        })
    }
}

/// A Python object as a hil [`Environment`]: `actions` (a list of action
/// names), `context_dim`, `reset(seed)`, `next_item()` (an item label, an
/// `Item` dict, or None at the end of the episode), `observe()` (a 1-d
/// float array), `execute(arm)` (a bool, or an `Outcome` dict) and
/// optionally `best_action()` (an arm index or None).
#[derive(Debug)]
pub(crate) struct PyEnvironment {
    held: Held,
    name: String,
    actions: ActionSpace,
    dim: usize,
    item: Option<Item>,
    items: usize,
    order: CallOrder,
}

impl PyEnvironment {
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>) -> PyResult<Self> {
        let held = Held::new(py, object, "environment");
        let bound = held.object.bind(py);
        let names: Vec<String> = bound.getattr("actions")?.extract()?;
        let actions = ActionSpace::new(names).map_err(crate::errors::to_py_err)?;
        let dim = required_usize(bound, "context_dim", &held.label)?;
        let name = name_of(bound);
        Ok(Self {
            held,
            actions,
            dim,
            item: None,
            items: 0,
            order: CallOrder::new(name.clone()),
            name,
        })
    }
}

/// The [`Environment`] methods of a wrapper that keeps the facts of the
/// environment it wraps (`name`, `actions`, `dim`) and the current `item`
/// (what a wrapped environment behind a lock or in Python cannot lend).
macro_rules! environment_facts {
    () => {
        fn name(&self) -> &str {
            &self.name
        }
        fn action_space(&self) -> &ActionSpace {
            &self.actions
        }
        fn context_dim(&self) -> usize {
            self.dim
        }
        fn current_item(&self) -> Option<&Item> {
            self.item.as_ref()
        }
    };
}
pub(crate) use environment_facts;

impl Environment for PyEnvironment {
    environment_facts!();

    fn reset(&mut self, seed: u64) -> Result<()> {
        self.item = None;
        self.items = 0;
        self.order.on_reset();
        self.held
            .call("reset", |o| o.call_method1("reset", (seed,)).map(drop))
    }

    fn next_item(&mut self) -> Result<Option<Item>> {
        let index = self.items;
        let item = self.held.call("next_item", |o| {
            let out = o.call_method0("next_item")?;
            if out.is_none() {
                return Ok(None);
            }
            if let Ok(label) = out.extract::<String>() {
                return Ok(Some(Item::new(index, label)));
            }
            from_py::<Item>(&out, "the item a Python environment returned").map(Some)
        })?;
        if item.is_some() {
            self.items += 1;
        }
        self.order.on_next_item(item.is_some());
        self.item = item.clone();
        Ok(item)
    }

    fn observe(&mut self) -> Result<Context> {
        self.order.on_observe()?;
        let values = self.held.call("observe", |o| {
            let out = o.call_method0("observe")?;
            let a: PyReadonlyArray1<'_, f64> = out.extract()?;
            Ok(a.as_array().to_vec())
        })?;
        let context = Context::new(values)?;
        context.check_dim(self.dim)?;
        Ok(context)
    }

    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.actions.check(arm)?;
        self.order.on_execute()?;
        self.held.call("execute", |o| {
            let out = o.call_method1("execute", (arm.0,))?;
            if let Ok(success) = out.extract::<bool>() {
                return Ok(Outcome::new(success));
            }
            from_py(&out, "the outcome a Python environment returned")
        })
    }

    fn best_action(&self) -> Option<ArmId> {
        if !self.held.has("best_action") {
            return None;
        }
        self.held
            .call("best_action", |o| {
                o.call_method0("best_action")?.extract::<Option<usize>>()
            })
            .ok()
            .flatten()
            .map(ArmId)
    }
}
