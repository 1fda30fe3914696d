//! hil's own components from Python: `hil.Policy`, `hil.Environment`,
//! `hil.QueryChannel` and `hil.WorkloadModel`, each built from a config
//! (its `type` and parameters, exactly as in an experiment TOML, so every
//! built-in and registered type is reachable), and the conversion of any
//! component argument (one of these, or a Python object with the right
//! methods) into the trait object hil's loop takes.

use std::path::PathBuf;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use hil_config::{BuildContext, TaskContext, limits};
use hil_config::{EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig};
use hil_core::{
    ActionSpace, ArmId, Attempt, Choice, Context, Decision, DecisionInput, Environment, Feedback,
    HilError, Item, LabelledObservation, Outcome, Policy, Query, QueryChannel, QueryHistory,
    QueryKind, Response, Result, Timestep, WorkloadForecast, WorkloadInput, WorkloadModel,
};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use serde_json::Value;

use crate::convert::{ContextArg, from_py, to_py};
use crate::errors::{IntoPy, to_py_err};
use crate::pycomponents::{
    PyChannel, PyEnvironment, PyPolicy, PyWorkload, environment_facts, policy_facts,
};

/// A component table (`{"type": ..., **params}`) from a type name and
/// keyword parameters.
pub(crate) fn table(ty: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<toml::Value> {
    let mut t = match params {
        Some(p) => match crate::convert::to_toml(p.as_any(), "parameters")? {
            toml::Value::Table(t) => t,
            _ => unreachable!("keyword arguments are a dict"),
        },
        None => toml::Table::new(),
    };
    t.insert("type".into(), toml::Value::String(ty.into()));
    Ok(toml::Value::Table(t))
}

/// Parses a component table as the config of one of the four kinds
/// (built-in or registered type), then runs its `validate`.
macro_rules! parse_config {
    ($fn:ident, $trait:ident) => {
        pub(crate) fn $fn(v: toml::Value) -> Result<Box<dyn $trait>> {
            let ty = v
                .get("type")
                .and_then(toml::Value::as_str)
                .unwrap_or("?")
                .to_string();
            let cfg: Box<dyn $trait> = hil_plugin::component(v).map_err(|e: toml::de::Error| {
                HilError::serde(format!("config of `{ty}`"), e.message().trim().to_string())
            })?;
            cfg.validate()?;
            Ok(cfg)
        }
    };
}
parse_config!(policy_config, PolicyConfig);
parse_config!(environment_config, EnvironmentConfig);
parse_config!(workload_config, WorkloadModelConfig);
parse_config!(channel_config, QueryChannelConfig);

/// `actions` as an action space: a count (`a0`, `a1`, ...; at most
/// [`limits::ARMS`], checked before the names are made, so `10**12` is an
/// error) or names.
pub(crate) fn action_space(actions: &Bound<'_, PyAny>) -> PyResult<ActionSpace> {
    // A bool extracts as a count (True = 1 action): refuse it instead.
    if actions.is_instance_of::<pyo3::types::PyBool>() {
        return Err(to_py_err(HilError::invalid_parameter(
            "actions",
            actions.to_string(),
            "give a count or a list of names, not a bool",
        )));
    }
    let names: Vec<String> = match actions.extract::<usize>() {
        Ok(n) => {
            limits::check_count("actions", n, limits::ARMS).py_err()?;
            (0..n).map(|i| format!("a{i}")).collect()
        }
        Err(_) => actions.extract()?,
    };
    ActionSpace::new(names).py_err()
}

/// Locks `m`, also after a panic elsewhere (the guard reported it).
fn lock<T: ?Sized>(m: &Mutex<Box<T>>) -> MutexGuard<'_, Box<T>> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

// ---------------------------------------------------------------- policies

/// A built policy with what it needs to decide on its own: the workload
/// model its forecasts use, WL_0, the queries it asked through `act`, and
/// the time spent inside its `decide` and `observe`.
pub(crate) struct PolicyState {
    policy: Box<dyn Policy>,
    forecast: Option<Arc<dyn WorkloadModel>>,
    wl0: f64,
    history: QueryHistory,
    inner: Duration,
}

impl PolicyState {
    /// The policy's `decide`, timed.
    pub(crate) fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let start = Instant::now();
        let decision = self.policy.decide(input);
        self.inner += start.elapsed();
        decision
    }

    /// The policy's `observe`, timed.
    pub(crate) fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        let start = Instant::now();
        let learnt = self.policy.observe(feedback);
        self.inner += start.elapsed();
        learnt
    }

    /// The policy's `decide` for `context` at `t` and item position `at`
    /// (item index, items seen, attempt), with the workload forecast of
    /// `model` from `wl0` given `history`.
    fn decide_at(
        &mut self,
        context: &Context,
        t: Timestep,
        at: (usize, usize, u32),
        model: Option<&dyn WorkloadModel>,
        wl0: f64,
        history: &QueryHistory,
    ) -> Result<Decision> {
        let forecast = WorkloadForecast::new(model, wl0, history, t);
        let input = DecisionInput::new(context, t, forecast).at_item(at.0, at.1, at.2);
        self.decide(&input)
    }

    /// Decides for `context` at `t` with its own forecast and query
    /// history, adding the query it asks (if any) to that history; returns
    /// the arm, or `n_arms` for "ask".
    fn act(&mut self, context: &Context, t: Timestep, at: (usize, usize, u32)) -> Result<usize> {
        // The policy's own forecast and history, borrowed without a copy.
        let history = std::mem::take(&mut self.history);
        let forecast = self.forecast.clone();
        let decision = self.decide_at(context, t, at, forecast.as_deref(), self.wl0, &history);
        self.history = history;
        Ok(match decision?.choice {
            Choice::Act { arm } => arm.0,
            Choice::Query { kind, .. } => {
                self.history.push(t, kind)?;
                self.policy.n_arms()
            }
        })
    }
}

/// A hil policy (any built-in or registered type).
///
/// Built from its type and hyperparameters, validated: e.g.
/// `Policy("linucb_qg", actions=6, dim=8, alpha=0.5, w=1.0)`. Bad values
/// raise `InvalidParameterError` naming the parameter. The environment's
/// facts come from `environment=` (which also gives pretraining data when
/// `pretrain=True`), or from `actions=` (a count or names) and `dim=`
/// (with `pretraining=(X, arms, rewards)` arrays if wanted). `forecast=`
/// (a `WorkloadModel`) and `wl0=` are what its own decisions forecast
/// workload with (`act`, and `decide` without `workload=`); the Gymnasium
/// environments hand out policies so set up (`HilEnv.policy`).
#[pyclass(module = "hil._hil", name = "Policy", frozen)]
pub(crate) struct PyPolicyHandle {
    pub(crate) inner: Arc<Mutex<PolicyState>>,
    /// The buffer the last context from Python was copied into, reused by
    /// the next call when nothing kept it (see [`PyPolicyHandle::context`]).
    scratch: Mutex<Option<Arc<[f64]>>>,
    name: String,
    n_arms: usize,
    dim: usize,
}

impl PyPolicyHandle {
    /// A handle on `policy`, whose own decisions forecast workload with
    /// `forecast` from `wl0`.
    pub(crate) fn new(
        policy: Box<dyn Policy>,
        forecast: Option<Arc<dyn WorkloadModel>>,
        wl0: f64,
    ) -> Result<Self> {
        hil_core::workload::check_wl0(wl0)?;
        Ok(Self {
            name: policy.name().to_string(),
            n_arms: policy.n_arms(),
            dim: policy.dim(),
            inner: Arc::new(Mutex::new(PolicyState {
                policy,
                forecast,
                wl0,
                history: QueryHistory::new(),
                inner: Duration::ZERO,
            })),
            scratch: Mutex::new(None),
        })
    }

    /// `array` as a context, copied into the buffer of the previous call
    /// when no one kept that one (a policy may keep a context; hil's copy
    /// what they learn): after a large policy's sweep has evicted the
    /// caches, allocating and freeing 16 KB costs a few tenths of a
    /// microsecond (hil-py/README.md, "Crossing into Rust"). The buffer's
    /// lock is only ever held for this copy; a call that finds it taken (by
    /// another thread) allocates instead of waiting.
    fn context(&self, array: &Bound<'_, PyArray1<f64>>) -> PyResult<Context> {
        let Ok(mut slot) = self.scratch.try_lock() else {
            return crate::convert::context(array);
        };
        let reused = slot
            .as_mut()
            .and_then(Arc::get_mut)
            .filter(|buf| buf.len() == numpy::PyUntypedArrayMethods::len(array))
            .is_some_and(|buf| crate::convert::copy_context(array, buf));
        match slot.clone() {
            Some(values) if reused => Context::new(values).py_err(),
            _ => {
                let values = crate::convert::values(array);
                *slot = Some(values.clone());
                Context::new(values).py_err()
            }
        }
    }

    /// The policy and its own state, locked.
    pub(crate) fn state(&self) -> MutexGuard<'_, PolicyState> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs `f` on the locked state. `light` work (small, or no policy call
    /// at all) keeps the GIL, since releasing and retaking it costs about as
    /// much as a small policy's whole call, unless another thread holds the
    /// state: that one (a session sharing this policy) may be waiting for
    /// the GIL, so this one waits for the lock without it.
    fn with_state<T: Send>(
        &self,
        py: Python<'_>,
        light: bool,
        f: impl FnOnce(&mut PolicyState) -> T + Send,
    ) -> T {
        if light && let Ok(mut state) = self.inner.try_lock() {
            return f(&mut state);
        }
        py.detach(|| f(&mut self.state()))
    }
}
/// The build context of a policy or channel from the Python arguments.
pub(crate) fn task_context(
    py: Python<'_>,
    environment: Option<&Bound<'_, PyEnvironmentHandle>>,
    actions: Option<&Bound<'_, PyAny>>,
    dim: Option<usize>,
    pretraining: Option<&Bound<'_, PyAny>>,
    seed: u64,
) -> PyResult<TaskContext> {
    if let Some(env) = environment {
        let env = env.borrow();
        let ctx = BuildContext::new(env.base_dir.clone(), seed);
        let built = lock(&env.inner);
        let task = match &env.config {
            Some(cfg) => ctx.describe_environment(cfg.as_ref(), built.as_ref()),
            None => Ok(TaskContext::new(
                ctx,
                built.action_space().clone(),
                built.context_dim(),
            )),
        };
        return task.py_err();
    }
    let (Some(actions), Some(dim)) = (actions, dim) else {
        return Err(to_py_err(HilError::invalid_input(
            "arguments",
            "give `environment=`, or both `actions=` and `dim=`",
        )));
    };
    let task = TaskContext::new(BuildContext::new(".", seed), action_space(actions)?, dim);
    match pretraining {
        None => Ok(task),
        Some(p) => {
            let (x, arms, rewards) = pretraining_arrays(py, p)?;
            let (x, arms, rewards): (
                PyReadonlyArray2<'_, f64>,
                PyReadonlyArray1<'_, i64>,
                PyReadonlyArray1<'_, f64>,
            ) = (x.extract()?, arms.extract()?, rewards.extract()?);
            let (x, arms, rewards) = (x.as_array(), arms.as_array(), rewards.as_array());
            if x.nrows() != arms.len() || x.nrows() != rewards.len() {
                return Err(to_py_err(HilError::invalid_input(
                    "pretraining",
                    format!(
                        "X has {} rows, arms {} and rewards {}",
                        x.nrows(),
                        arms.len(),
                        rewards.len()
                    ),
                )));
            }
            let mut data = Vec::with_capacity(x.nrows());
            for (i, row) in x.rows().into_iter().enumerate() {
                let arm = usize::try_from(arms[i]).map_err(|_| {
                    to_py_err(HilError::invalid_input(
                        format!("pretraining arms[{i}]"),
                        format!("{} is negative", arms[i]),
                    ))
                })?;
                let context = Context::new(row.to_vec())
                    .map_err(|e| {
                        HilError::invalid_input(format!("pretraining X[{i}]"), e.to_string())
                    })
                    .py_err()?;
                data.push(LabelledObservation {
                    context,
                    arm: ArmId(arm),
                    reward: rewards[i],
                });
            }
            Ok(task.with_pretraining(data.into()))
        }
    }
}

/// `pretraining=(X, arms, rewards)` as NumPy arrays of the types the
/// policy reads (X float64 n × d, arms int64, rewards float64), converted
/// from any array-like (a list, float32, int32), each error naming the
/// part at fault. Arms must be whole numbers: 0.5 is refused, never
/// truncated.
fn pretraining_arrays<'py>(
    py: Python<'py>,
    p: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let refuse = |what: &str, why: String| {
        to_py_err(HilError::invalid_input(format!("pretraining {what}"), why))
    };
    let (x, arms, rewards): (Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>) = p
        .extract()
        .map_err(|_| refuse("", "expected a tuple (X, arms, rewards) of arrays".into()))?;
    let numpy = PyModule::import(py, "numpy")?;
    let array = |v: &Bound<'py, PyAny>, what: &str, ndim: usize| -> PyResult<Bound<'py, PyAny>> {
        let a = numpy
            .call_method1("asarray", (v,))
            .map_err(|e| refuse(what, format!("not an array ({e})")))?;
        let shape = a.getattr("shape")?;
        if a.getattr("ndim")?.extract::<usize>()? != ndim {
            return Err(refuse(what, format!("must be {ndim}-d, got shape {shape}")));
        }
        Ok(a)
    };
    let kind = |a: &Bound<'py, PyAny>| -> PyResult<String> {
        a.getattr("dtype")?.getattr("kind")?.extract()
    };
    let float = |v: &Bound<'py, PyAny>, what: &str, ndim: usize| -> PyResult<Bound<'py, PyAny>> {
        let a = array(v, what, ndim)?;
        if !"fiub".contains(kind(&a)?.as_str()) {
            return Err(refuse(
                what,
                format!("must hold numbers, not {}", a.getattr("dtype")?),
            ));
        }
        a.call_method1("astype", ("float64",))
    };
    let x = float(&x, "X", 2)?;
    let rewards = float(&rewards, "rewards", 1)?;
    let arms = array(&arms, "arms", 1)?;
    if !"iu".contains(kind(&arms)?.as_str()) {
        return Err(refuse(
            "arms",
            format!("must hold whole numbers, not {}", arms.getattr("dtype")?),
        ));
    }
    Ok((x, arms.call_method1("astype", ("int64",))?, rewards))
}

#[pymethods]
impl PyPolicyHandle {
    #[new]
    #[pyo3(signature = (r#type, /, *, environment=None, actions=None, dim=None, pretraining=None, seed=0, forecast=None, wl0=0.5, **params))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        r#type: &str,
        environment: Option<&Bound<'_, PyEnvironmentHandle>>,
        actions: Option<&Bound<'_, PyAny>>,
        dim: Option<usize>,
        pretraining: Option<&Bound<'_, PyAny>>,
        seed: u64,
        forecast: Option<&Bound<'_, PyAny>>,
        wl0: f64,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        // Arrays given for a policy that will not pretrain would be
        // silently unused.
        let pretrains = match params
            .map(|p| p.get_item("pretrain"))
            .transpose()?
            .flatten()
        {
            Some(v) => v.is_truthy()?,
            None => false,
        };
        if pretraining.is_some() && !pretrains {
            return Err(to_py_err(HilError::invalid_parameter(
                "pretraining",
                "(arrays)",
                "given, but the policy does not pretrain: add pretrain=True",
            )));
        }
        let cfg = policy_config(table(r#type, params)?).py_err()?;
        let ctx = task_context(py, environment, actions, dim, pretraining, seed)?;
        let forecast = forecast.map(workload_arg).transpose()?;
        let policy = py.detach(|| cfg.build(&ctx)).py_err()?;
        Self::new(policy, forecast, wl0).py_err()
    }

    /// The policy's short name (e.g. `linucb_qg`).
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Number of robot actions; `act` returns this for "ask".
    #[getter]
    pub(crate) fn n_arms(&self) -> usize {
        self.n_arms
    }

    /// Context dimension.
    #[getter]
    pub(crate) fn dim(&self) -> usize {
        self.dim
    }

    /// Reseeds the policy's own randomness.
    fn seed(&self, py: Python<'_>, seed: u64) {
        self.with_state(py, true, |s| s.policy.seed(seed));
    }

    /// Decides for `context` (1-d float array) at timestep `t`: returns the
    /// `Decision` as a dict (`choice`: `{"type": "act", "arm": k}` or
    /// `{"type": "query", "kind": ..., "fallback": k}`; `diagnostics`).
    /// LinUCB-QG weighs the workload forecast by `workload` (a
    /// `WorkloadModel`; default the policy's `forecast=`) from `wl0`
    /// (default the policy's) given the queries asked at `query_times`
    /// (default those it asked through `act`). Nothing is recorded: use
    /// `act` for a policy that acts on its own.
    #[pyo3(signature = (context, t=1, *, workload=None, wl0=None, query_times=None, item_index=0, items_seen=0, attempt=0))]
    #[allow(clippy::too_many_arguments)]
    fn decide(
        &self,
        py: Python<'_>,
        context: ContextArg<'_>,
        t: u64,
        workload: Option<&Bound<'_, PyWorkloadHandle>>,
        wl0: Option<f64>,
        query_times: Option<Vec<u64>>,
        item_index: usize,
        items_seen: usize,
        attempt: u32,
    ) -> PyResult<Py<PyAny>> {
        let x = self.context(&context.0)?;
        let given = query_times.map(|q| history_of(&q)).transpose()?;
        let model = workload.map(|w| w.get().inner.clone());
        let decision: Decision = py
            .detach(|| {
                let mut state = self.state();
                let model = model.or_else(|| state.forecast.clone());
                let wl0 = wl0.unwrap_or(state.wl0);
                let history = given.unwrap_or_else(|| state.history.clone());
                let at = (item_index, items_seen, attempt);
                state.decide_at(&x, t, at, model.as_deref(), wl0, &history)
            })
            .py_err()?;
        to_py(py, &decision, "decision")
    }

    /// Decides for `context` at `t` as an agent on its own: returns the arm
    /// to execute, or `n_arms` to ask (a Gymnasium agent's action). The
    /// forecast is the policy's own (`forecast=`, `wl0=`, and the queries it
    /// asked through `act`, to which an "ask" is added). The fast path: no
    /// dict is built.
    #[pyo3(signature = (context, t=1, *, item_index=0, items_seen=0, attempt=0))]
    fn act(
        &self,
        py: Python<'_>,
        context: ContextArg<'_>,
        t: u64,
        item_index: usize,
        items_seen: usize,
        attempt: u32,
    ) -> PyResult<usize> {
        let x = self.context(&context.0)?;
        let light = self.dim < DETACH_MIN_DIM;
        self.with_state(py, light, |s| {
            s.act(&x, t, (item_index, items_seen, attempt))
        })
        .py_err()
    }

    /// Learns from executing `arm` in `context` with `reward` at `t`
    /// (`from_expert`: the arm was the person's answer).
    #[pyo3(signature = (context, arm, reward, t=1, from_expert=false))]
    fn observe(
        &self,
        py: Python<'_>,
        context: ContextArg<'_>,
        arm: usize,
        reward: f64,
        t: u64,
        from_expert: bool,
    ) -> PyResult<()> {
        let x = self.context(&context.0)?;
        let attempt = Attempt {
            context: &x,
            arm: ArmId(arm),
            reward,
            t,
        };
        let feedback = Feedback::new(attempt).from_expert(from_expert);
        let light = self.dim < DETACH_MIN_DIM;
        self.with_state(py, light, |s| s.observe(&feedback))
            .py_err()
    }

    /// The times of the queries the policy asked through `act`.
    #[getter]
    fn query_times(&self, py: Python<'_>) -> Vec<u64> {
        self.with_state(py, true, |s| {
            s.history.records().iter().map(|r| r.t).collect()
        })
    }

    /// Forgets the queries asked through `act` (a new episode's person).
    fn clear_queries(&self, py: Python<'_>) {
        self.with_state(py, true, |s| s.history = QueryHistory::new());
    }

    /// Seconds spent inside the policy's own `decide` and `observe` so far,
    /// whoever called them (`act`, `decide`, `observe`, a session, a
    /// Gymnasium environment): what `hil bench policy` times, so that the
    /// rest of a call's time is the cost of crossing from Python.
    #[getter]
    fn inner_seconds(&self, py: Python<'_>) -> f64 {
        self.with_state(py, true, |s| s.inner.as_secs_f64())
    }

    /// The full learning state as a JSON string (estimates, RNG, counters).
    fn save(&self, py: Python<'_>) -> PyResult<String> {
        let state = py.detach(|| self.state().policy.save()).py_err()?;
        serde_json::to_string(&state)
            .map_err(|e| HilError::serde("policy state", e))
            .py_err()
    }

    /// Restores a state from `save()` (a JSON string or its parsed form).
    fn restore(&self, py: Python<'_>, state: &Bound<'_, PyAny>) -> PyResult<()> {
        let value: Value = match state.extract::<String>() {
            Ok(text) => serde_json::from_str(&text)
                .map_err(|e| HilError::serde("policy state", e))
                .py_err()?,
            Err(_) => from_py(state, "policy state")?,
        };
        py.detach(|| self.state().policy.restore(value)).py_err()
    }

    /// The diagnostics of a decision for `context` as a dict (per-arm
    /// estimate, bonus and UCB; gap, threshold, query probability and
    /// workload forecast where the policy computes them): `decide`'s, with
    /// the same arguments. It decides to get them, so a stochastic
    /// policy's random stream advances.
    #[pyo3(signature = (context, t=1, **decide_args))]
    fn diagnostics(
        slf: &Bound<'_, Self>,
        context: ContextArg<'_>,
        t: u64,
        decide_args: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Py<PyAny>> {
        let d = slf.call_method("decide", (context.0, t), decide_args)?;
        Ok(d.get_item("diagnostics")?.unbind())
    }

    fn __repr__(&self) -> String {
        format!(
            "Policy({:?}, n_arms={}, dim={})",
            self.name, self.n_arms, self.dim
        )
    }
}

/// The context dimension from which a policy call releases the GIL (see
/// [`PyPolicyHandle::with_state`]): LinUCB-QG's decide + observe take ~2 µs at d = 16 and
/// ~5-15 µs at d = 128 (300 pretraining rows per arm), releasing and
/// retaking the GIL ~0.1-0.3 µs (hil-py/README.md, "Crossing into Rust").
const DETACH_MIN_DIM: usize = 128;

fn history_of(times: &[u64]) -> PyResult<QueryHistory> {
    let mut h = QueryHistory::new();
    for &t in times {
        h.push(t, QueryKind::default()).py_err()?;
    }
    Ok(h)
}

/// A shared hil policy as a trait object: every call locks it, so the
/// Python handle sees what the loop taught it.
struct SharedPolicy {
    inner: Arc<Mutex<PolicyState>>,
    name: String,
    n_arms: usize,
    dim: usize,
}

impl SharedPolicy {
    fn state(&self) -> MutexGuard<'_, PolicyState> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Policy for SharedPolicy {
    policy_facts!();
    fn seed(&mut self, seed: u64) {
        self.state().policy.seed(seed)
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        self.state().decide(input)
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        self.state().observe(feedback)
    }
    fn save(&self) -> Result<Value> {
        self.state().policy.save()
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        self.state().policy.restore(state)
    }
}

/// A policy argument: a `hil.Policy` (shared) or a Python object with the
/// policy methods.
pub(crate) fn policy_arg(obj: &Bound<'_, PyAny>) -> PyResult<Box<dyn Policy>> {
    if let Ok(h) = obj.cast::<PyPolicyHandle>() {
        let h = h.get();
        return Ok(Box::new(SharedPolicy {
            inner: h.inner.clone(),
            name: h.name.clone(),
            n_arms: h.n_arms,
            dim: h.dim,
        }));
    }
    Ok(Box::new(PyPolicy::new(obj.py(), obj.clone().unbind())?))
}

// ------------------------------------------------------------ environments

/// A hil environment (any built-in or registered type), e.g. the dataset
/// replay `Environment("food_replay", foods=[...], pretrain_foods=[...])`.
/// Relative paths in the parameters resolve against `base_dir`.
#[pyclass(module = "hil._hil", name = "Environment")]
pub(crate) struct PyEnvironmentHandle {
    pub(crate) inner: Arc<Mutex<Box<dyn Environment>>>,
    pub(crate) config: Option<Arc<dyn EnvironmentConfig>>,
    pub(crate) base_dir: PathBuf,
    name: String,
    actions: ActionSpace,
    dim: usize,
}

#[pymethods]
impl PyEnvironmentHandle {
    #[new]
    #[pyo3(signature = (r#type, /, *, seed=0, base_dir=None, **params))]
    fn py_new(
        py: Python<'_>,
        r#type: &str,
        seed: u64,
        base_dir: Option<PathBuf>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let cfg: Arc<dyn EnvironmentConfig> =
            Arc::from(environment_config(table(r#type, params)?).py_err()?);
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        let ctx = BuildContext::new(base_dir.clone(), seed);
        let env = py.detach(|| cfg.build(&ctx)).py_err()?;
        Ok(Self {
            name: env.name().to_string(),
            actions: env.action_space().clone(),
            dim: env.context_dim(),
            inner: Arc::new(Mutex::new(env)),
            config: Some(cfg),
            base_dir,
        })
    }

    /// The environment's short name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The names of the robot actions.
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.actions.names().to_vec()
    }

    /// Context dimension.
    #[getter]
    fn context_dim(&self) -> usize {
        self.dim
    }

    /// Starts an episode seeded by `seed`.
    fn reset(&self, py: Python<'_>, seed: u64) -> PyResult<()> {
        py.detach(|| lock(&self.inner).reset(seed)).py_err()
    }

    /// The next item as a dict (`index`, `label`, `description`), or None
    /// at the end of the episode.
    fn next_item(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let item: Option<Item> = py.detach(|| lock(&self.inner).next_item()).py_err()?;
        to_py(py, &item, "item")
    }

    /// A fresh context of the current item (1-d float array).
    fn observe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let x = py.detach(|| lock(&self.inner).observe()).py_err()?;
        Ok(crate::convert::array(py, &x))
    }

    /// Executes `arm`; returns the `Outcome` as a dict (`success`,
    /// `success_probability`, ...).
    fn execute(&self, py: Python<'_>, arm: usize) -> PyResult<Py<PyAny>> {
        let o: Outcome = py
            .detach(|| lock(&self.inner).execute(ArmId(arm)))
            .py_err()?;
        to_py(py, &o, "outcome")
    }

    /// The best action for the current observation, if known (simulation).
    fn best_action(&self) -> Option<usize> {
        lock(&self.inner).best_action().map(|a| a.0)
    }

    fn __repr__(&self) -> String {
        format!(
            "Environment({:?}, actions={}, context_dim={})",
            self.name,
            self.actions.len(),
            self.dim
        )
    }
}

struct SharedEnvironment {
    inner: Arc<Mutex<Box<dyn Environment>>>,
    name: String,
    actions: ActionSpace,
    dim: usize,
    item: Option<Item>,
}

impl Environment for SharedEnvironment {
    environment_facts!();
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.item = None;
        lock(&self.inner).reset(seed)
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        let item = lock(&self.inner).next_item()?;
        self.item = item.clone();
        Ok(item)
    }
    fn observe(&mut self) -> Result<Context> {
        lock(&self.inner).observe()
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        lock(&self.inner).execute(arm)
    }
    fn best_action(&self) -> Option<ArmId> {
        lock(&self.inner).best_action()
    }
}

/// A built environment and its config, when it has one.
pub(crate) type BuiltEnvironment = (Box<dyn Environment>, Option<Arc<dyn EnvironmentConfig>>);

/// An environment argument: a `hil.Environment` (shared) or a Python
/// object with the environment methods; with its config when it has one
/// (for pretraining data).
pub(crate) fn environment_arg(obj: &Bound<'_, PyAny>) -> PyResult<BuiltEnvironment> {
    if let Ok(h) = obj.cast::<PyEnvironmentHandle>() {
        let h = h.borrow();
        let env = SharedEnvironment {
            inner: h.inner.clone(),
            name: h.name.clone(),
            actions: h.actions.clone(),
            dim: h.dim,
            item: None,
        };
        return Ok((Box::new(env), h.config.clone()));
    }
    Ok((
        Box::new(PyEnvironment::new(obj.py(), obj.clone().unbind())?),
        None,
    ))
}

// ---------------------------------------------------------- query channels

/// A hil query channel (any built-in or registered type), e.g.
/// `QueryChannel("simulated_expert", error_rate=0.1)` (built for
/// `environment=`, or `actions=` and `dim=`).
#[pyclass(module = "hil._hil", name = "QueryChannel")]
pub(crate) struct PyChannelHandle {
    inner: Arc<Mutex<Box<dyn QueryChannel>>>,
    name: String,
}

#[pymethods]
impl PyChannelHandle {
    #[new]
    #[pyo3(signature = (r#type, /, *, environment=None, actions=None, dim=None, seed=0, **params))]
    fn py_new(
        py: Python<'_>,
        r#type: &str,
        environment: Option<&Bound<'_, PyEnvironmentHandle>>,
        actions: Option<&Bound<'_, PyAny>>,
        dim: Option<usize>,
        seed: u64,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let cfg = channel_config(table(r#type, params)?).py_err()?;
        let ctx = task_context(py, environment, actions, dim, None, seed)?;
        let ch = cfg.build(&ctx).py_err()?;
        Ok(Self {
            name: ch.name().to_string(),
            inner: Arc::new(Mutex::new(ch)),
        })
    }

    /// The channel's short name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Reseeds a simulated channel.
    fn seed(&self, seed: u64) {
        lock(&self.inner).seed(seed)
    }

    /// Asks `query` (the serde form of a `Query` as a dict) and returns the
    /// `Response` as a dict.
    fn ask(&self, py: Python<'_>, query: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let q: Query = from_py(query, "query")?;
        let r: Response = py.detach(|| lock(&self.inner).ask(&q)).py_err()?;
        to_py(py, &r, "response")
    }
}

struct SharedChannel {
    inner: Arc<Mutex<Box<dyn QueryChannel>>>,
    name: String,
}

impl QueryChannel for SharedChannel {
    fn name(&self) -> &str {
        &self.name
    }
    fn seed(&mut self, seed: u64) {
        lock(&self.inner).seed(seed)
    }
    fn endpoint(&self) -> Option<String> {
        lock(&self.inner).endpoint()
    }
    fn ask(&mut self, query: &Query) -> Result<Response> {
        lock(&self.inner).ask(query)
    }
}

/// A channel argument: a `hil.QueryChannel`, a Python object with `ask`,
/// or None for the perfect expert of the paper's simulations.
pub(crate) fn channel_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Box<dyn QueryChannel>> {
    let Some(obj) = obj else {
        return Ok(Box::new(hil_core::PerfectExpert::default()));
    };
    if let Ok(h) = obj.cast::<PyChannelHandle>() {
        let h = h.borrow();
        return Ok(Box::new(SharedChannel {
            inner: h.inner.clone(),
            name: h.name.clone(),
        }));
    }
    Ok(Box::new(PyChannel::new(obj.py(), obj.clone().unbind())))
}

// --------------------------------------------------------- workload models

/// A workload model WL_t = f(WL_0, Q_t): `WorkloadModel.bundled("f2_sim")`,
/// `WorkloadModel.from_file(path)`, `hil.fit_workload(...)`, or any
/// registered type: `WorkloadModel("demo_counting", step=0.1)`.
#[pyclass(module = "hil._hil", name = "WorkloadModel", frozen)]
pub(crate) struct PyWorkloadHandle {
    pub(crate) inner: Arc<dyn WorkloadModel>,
}

impl PyWorkloadHandle {
    pub(crate) fn of(inner: Arc<dyn WorkloadModel>) -> Self {
        Self { inner }
    }
}

/// Query kinds from their display strings (`mcq`, `open/hard`, ...), one
/// per query time; all the default kind when None.
fn kinds_of(kinds: Option<Vec<String>>, n: usize) -> PyResult<Vec<QueryKind>> {
    match kinds {
        None => Ok(vec![QueryKind::default(); n]),
        Some(k) => {
            if k.len() != n {
                return Err(to_py_err(HilError::invalid_input(
                    "kinds",
                    format!("{} kinds for {n} query times", k.len()),
                )));
            }
            k.iter()
                .map(|s| {
                    s.parse::<QueryKind>()
                        .map_err(|e| to_py_err(HilError::invalid_input("kinds", e.to_string())))
                })
                .collect()
        }
    }
}

#[pymethods]
impl PyWorkloadHandle {
    #[new]
    #[pyo3(signature = (r#type, /, *, base_dir=None, **params))]
    fn py_new(
        py: Python<'_>,
        r#type: &str,
        base_dir: Option<PathBuf>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let cfg = workload_config(table(r#type, params)?).py_err()?;
        let ctx = BuildContext::new(base_dir.unwrap_or_else(|| ".".into()), 0);
        Ok(Self::of(py.detach(|| cfg.build(&ctx)).py_err()?))
    }

    /// A model bundled with hil (`f1_sim`, `f2_sim`, `f12_sim`, their
    /// `_steep` ends, `f1_real`, `f12_real`; synthetic, calibrated to
    /// published figures).
    #[staticmethod]
    fn bundled(name: &str) -> PyResult<Self> {
        Ok(Self::of(hil_workload::bundled::load(name).py_err()?))
    }

    /// The names of the bundled models.
    #[staticmethod]
    fn bundled_names() -> Vec<String> {
        hil_workload::bundled::NAMES
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    /// A model JSON file written by `hil workload fit` or `fit_workload`.
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        Ok(Self::of(hil_workload::load_model_json(path).py_err()?))
    }

    /// The model's short name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }

    /// WL_t from the initial workload `wl0` and the queries asked at
    /// `query_times` (with `kinds`, e.g. `"mcq"`, default the easy
    /// multiple-choice query), at timestep `t`.
    #[pyo3(signature = (wl0, query_times, t, kinds=None))]
    fn predict(
        &self,
        wl0: f64,
        query_times: Vec<u64>,
        t: u64,
        kinds: Option<Vec<String>>,
    ) -> PyResult<f64> {
        let h = history_with(&query_times, kinds)?;
        self.inner.predict(&WorkloadInput::new(wl0, &h, t)).py_err()
    }

    /// WL_t if a query of `kind` were asked now, at `t`.
    #[pyo3(signature = (wl0, query_times, t, kinds=None, kind=None))]
    fn predict_if_queried(
        &self,
        wl0: f64,
        query_times: Vec<u64>,
        t: u64,
        kinds: Option<Vec<String>>,
        kind: Option<String>,
    ) -> PyResult<f64> {
        let h = history_with(&query_times, kinds)?;
        let kind = kinds_of(kind.map(|k| vec![k]), 1)?[0];
        self.inner
            .predict_if_queried(&WorkloadInput::new(wl0, &h, t), kind)
            .py_err()
    }

    /// WL_t at every t in 0..=steps (a 1-d array) for queries asked at
    /// `query_times` (`kinds` as in `predict`); WL_0 at t = 0. Steps are
    /// Δt = 10 s.
    #[pyo3(signature = (query_times, steps=None, *, wl0=0.5, kinds=None))]
    fn rollout<'py>(
        &self,
        py: Python<'py>,
        query_times: Vec<u64>,
        steps: Option<u64>,
        wl0: f64,
        kinds: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let kinds = kinds_of(kinds, query_times.len())?;
        // Any order here; `schedule[i]` in an error counts in time order.
        let mut schedule: Vec<(u64, QueryKind)> = query_times.into_iter().zip(kinds).collect();
        schedule.sort_by_key(|q| q.0);
        let end = steps.unwrap_or_else(|| hil_workload::rollout::default_end(&schedule));
        let model = self.inner.clone();
        let curve = py
            .detach(|| hil_workload::rollout::rollout(model.as_ref(), wl0, &schedule, end))
            .py_err()?;
        Ok(PyArray1::from_vec(
            py,
            curve.into_iter().map(|s| s.wl).collect(),
        ))
    }

    fn __repr__(&self) -> String {
        format!("WorkloadModel({:?})", self.inner.name())
    }
}

fn history_with(times: &[u64], kinds: Option<Vec<String>>) -> PyResult<QueryHistory> {
    let kinds = kinds_of(kinds, times.len())?;
    let mut h = QueryHistory::new();
    for (&t, k) in times.iter().zip(kinds) {
        h.push(t, k).py_err()?;
    }
    Ok(h)
}

/// A workload-model argument: a `hil.WorkloadModel`, a bundled model's
/// name, or a Python object with `predict`.
pub(crate) fn workload_arg(obj: &Bound<'_, PyAny>) -> PyResult<Arc<dyn WorkloadModel>> {
    if let Ok(h) = obj.cast::<PyWorkloadHandle>() {
        return Ok(h.get().inner.clone());
    }
    if let Ok(name) = obj.cast::<PyString>() {
        return hil_workload::bundled::load(&name.to_cow()?).py_err();
    }
    Ok(Arc::new(PyWorkload::new(obj.py(), obj.clone().unbind())))
}

/// The serde form of a query kind (`{"response": ..., "difficulty": ...,
/// "distraction": ...}`) from its spelling `response/difficulty/distraction`
/// (`"mcq"`, `"open_ended/hard"`; parts left out take the default); an
/// unknown word raises `InvalidParameterError` naming it.
#[pyfunction]
fn query_kind(py: Python<'_>, kind: &str) -> PyResult<Py<PyAny>> {
    let kind: QueryKind = kind.parse().py_err()?;
    to_py(py, &kind, "query kind")
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(query_kind, m)?)?;
    m.add_class::<PyPolicyHandle>()?;
    m.add_class::<PyEnvironmentHandle>()?;
    m.add_class::<PyChannelHandle>()?;
    m.add_class::<PyWorkloadHandle>()?;
    Ok(())
}
