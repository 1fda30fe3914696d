//! Native engine of `hil.envs`: hil's session loop driven one decision at a
//! time by a Gymnasium agent, which may be a `hil.Policy` (`act` / `learn`).
//!
//! The engine drives the steppable session ([`hil_core::session::step`]) on
//! the caller's thread: `reset` starts an episode and moves it to the first
//! decision ([`Session::next_decision`]); `step` feeds the agent's action
//! ([`Session::feed_decision`]) and moves on to the next decision. So a
//! Gymnasium step is exactly one decision of the policy, followed by every
//! attempt the session executes before it asks the policy again (one
//! attempt after an autonomous action; after a query, the expert's arm
//! repeated until success or `n_att`), with the session's items, attempts,
//! workload tracker and checks. A new `reset` abandons the running episode.

use std::sync::{Arc, Mutex, MutexGuard};

use hil_config::{BuildContext, TaskContext};
use hil_config::{
    EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig, check_session_limits,
};
use hil_core::{
    ArmId, Attempt, Choice, Context, Decision, DecisionInput, Environment, Episode, EpisodeReport,
    Feedback, HilError, Policy, QueryChannel, QueryKind, Session, SessionSettings, StepEvent,
    Timestep, WorkloadModel,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Deserialize;

use crate::components::PyPolicyHandle;
use crate::errors::to_py_err;

/// What the environment of a [`GymCore`] is made of (JSON from Python):
/// the session settings, the environment, workload model and query channel
/// exactly as in an experiment config, and how the "ask" action asks.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GymConfig {
    /// Seed of the components' construction (e.g. the pretraining data);
    /// episodes are seeded by `reset`.
    #[serde(default)]
    build_seed: u64,
    #[serde(default)]
    session: SessionSettings,
    #[serde(deserialize_with = "hil_plugin::component")]
    environment: Box<dyn EnvironmentConfig>,
    #[serde(deserialize_with = "hil_plugin::component")]
    workload: Box<dyn WorkloadModelConfig>,
    #[serde(deserialize_with = "hil_plugin::component")]
    channel: Box<dyn QueryChannelConfig>,
    /// What the "ask" action asks.
    #[serde(default)]
    query_kind: QueryKind,
    /// The arm executed when the channel gives no arm back (a declined or
    /// timed-out query); the default simulated expert always answers.
    #[serde(default)]
    fallback_arm: usize,
}

/// What the agent sees when it must decide, read from the session's
/// decision input.
#[derive(Clone, Debug)]
struct Pending {
    context: Context,
    t: Timestep,
    item_index: usize,
    item_label: String,
    items_seen: usize,
    attempt: u32,
    n_queries: usize,
    wl_now: f64,
    wl_if_ask: f64,
}

impl Pending {
    /// The decision `episode` awaits, if any; `kind` is what "ask" asks.
    fn of(episode: &Episode, kind: QueryKind) -> hil_core::Result<Option<Self>> {
        let Some(input) = episode.pending() else {
            return Ok(None);
        };
        Ok(Some(Self {
            context: input.context.clone(),
            t: input.t,
            item_index: input.item_index,
            item_label: episode.item().map(|i| i.label.clone()).unwrap_or_default(),
            items_seen: input.items_seen,
            attempt: input.attempt,
            n_queries: input.workload.history().len(),
            wl_now: input.workload.now()?,
            wl_if_ask: input.workload.if_queried(kind)?,
        }))
    }
}

/// The policy of the engine's session: the agent decides outside the
/// session (`step` feeds its action) and learns from `info`, so this
/// policy only states the shape the session checks.
struct Agent {
    n_arms: usize,
    dim: usize,
}

impl Policy for Agent {
    fn name(&self) -> &str {
        "gymnasium_agent"
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn decide(&mut self, _: &DecisionInput<'_>) -> hil_core::Result<Decision> {
        Err(HilError::state(
            "gymnasium agent",
            "it decides outside the session: its action is fed by step()",
        ))
    }
    fn observe(&mut self, _: &Feedback<'_>) -> hil_core::Result<()> {
        Ok(())
    }
}

/// The components, the episode in progress and what its last step did.
struct Engine {
    environment: Box<dyn Environment>,
    channel: Box<dyn QueryChannel>,
    agent: Agent,
    episode: Option<Episode>,
    /// The attempts executed by the last step.
    executed: Vec<StepEvent>,
    /// The report, once the episode has ended.
    report: Option<EpisodeReport>,
}

/// The session loop driven one decision at a time (the engine of
/// `hil.envs.HilEnv`; see that class for the Gymnasium semantics).
#[pyclass(module = "hil._hil", frozen)]
pub(crate) struct GymCore {
    settings: SessionSettings,
    workload: Arc<dyn WorkloadModel>,
    task: TaskContext,
    kind: QueryKind,
    fallback: ArmId,
    environment_name: String,
    engine: Mutex<Engine>,
}

impl GymCore {
    fn engine(&self) -> PyResult<MutexGuard<'_, Engine>> {
        self.engine
            .lock()
            .map_err(|_| to_py_err(HilError::state("gymnasium environment", "a step panicked")))
    }

    /// Runs `f` with the engine's session and its episode slot, the
    /// executed attempts and the report.
    fn with_session<T>(
        &self,
        engine: &mut Engine,
        f: impl FnOnce(
            &mut Session<'_>,
            &mut Option<Episode>,
            &mut Vec<StepEvent>,
            &mut Option<EpisodeReport>,
        ) -> hil_core::Result<T>,
    ) -> hil_core::Result<T> {
        let Engine {
            environment,
            channel,
            agent,
            episode,
            executed,
            report,
        } = engine;
        let mut session = Session::new(
            self.settings.clone(),
            environment.as_mut(),
            agent,
            channel.as_mut(),
            self.workload.clone(),
        );
        f(&mut session, episode, executed, report)
    }
}

/// Moves `episode` on to its next decision, or finishes it when no item is
/// left, returning its report then; the attempts executed from event
/// `from` on are copied into `executed`.
fn advance(
    session: &mut Session<'_>,
    episode: &mut Episode,
    from: usize,
    executed: &mut Vec<StepEvent>,
) -> hil_core::Result<Option<EpisodeReport>> {
    let more = session.next_decision(episode, &mut [])?.is_some();
    let report = if more {
        None
    } else {
        Some(session.finish_episode(episode, &mut [])?)
    };
    let events = report.as_ref().map_or(episode.events(), |r| &r.events);
    executed.clear();
    executed.extend_from_slice(events.get(from..).unwrap_or_default());
    Ok(report)
}

fn context_array<'py>(py: Python<'py>, c: &Context) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, c.as_slice())
}

#[pymethods]
impl GymCore {
    /// Builds the environment, workload model and query channel from
    /// `config_json` (keys `session`, `environment`, `workload`, `channel`,
    /// and optionally `build_seed`, `query_kind`, `fallback_arm`; the
    /// components' tables as in an experiment config). Relative paths
    /// resolve against `base_dir`.
    #[new]
    #[pyo3(signature = (config_json, base_dir = "."))]
    fn new(py: Python<'_>, config_json: &str, base_dir: &str) -> PyResult<Self> {
        let config: GymConfig = crate::convert::from_json("environment config", config_json)?;
        py.detach(|| Self::build(config, base_dir))
            .map_err(to_py_err)
    }

    /// Number of robot actions (the "ask" action is `n_arms`).
    #[getter]
    fn n_arms(&self) -> usize {
        self.task.action_space().len()
    }

    /// Context dimension.
    #[getter]
    fn dim(&self) -> usize {
        self.task.context_dim()
    }

    /// The robot actions' names, in arm order.
    #[getter]
    fn action_names(&self) -> Vec<String> {
        self.task.action_space().names().to_vec()
    }

    /// The environment's name.
    #[getter]
    fn environment_name(&self) -> String {
        self.environment_name.clone()
    }

    /// Starts the episode seeded by `seed` (abandoning any running one) and
    /// returns the first context and the decision info.
    fn reset<'py>(
        &self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
        let mut guard = self.engine()?;
        let engine: &mut Engine = &mut guard;
        let pending = py.detach(|| self.start(engine, seed)).map_err(to_py_err)?;
        let Some(p) = pending else {
            return Err(to_py_err(HilError::state(
                "gymnasium environment",
                format!(
                    "`{}` ended its episode before the first decision (no items)",
                    self.environment_name
                ),
            )));
        };
        let info = PyDict::new(py);
        pending_info(&info, &p)?;
        Ok((context_array(py, &p.context), info))
    }

    /// Takes action `action` (an arm, or `n_arms` to ask) and returns
    /// `(observation, task_reward, wl_before, wl_after, terminated, info)`.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &self,
        py: Python<'py>,
        action: usize,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        f64,
        f64,
        f64,
        bool,
        Bound<'py, PyDict>,
    )> {
        let n_arms = self.n_arms();
        if action > n_arms {
            return Err(PyValueError::new_err(format!(
                "action {action} is outside 0..={n_arms} (arms 0..{n_arms}, {n_arms} = ask)"
            )));
        }
        let decision = if action == n_arms {
            Decision::query(self.kind, self.fallback)
        } else {
            Decision::act(ArmId(action))
        };
        let mut guard = self.engine()?;
        let engine: &mut Engine = &mut guard;
        let (before, after) = py
            .detach(|| self.feed(engine, decision))
            .map_err(to_py_err)?;
        let engine: &Engine = engine;

        let info = PyDict::new(py);
        let executed = &engine.executed;
        let reward: f64 = executed.iter().map(StepEvent::task_reward).sum();
        let wl_after = executed.last().map_or(before.wl_now, |e| e.step.wl_t);
        let (mut asked, mut expert_arm) = (false, None);
        for e in executed {
            if e.step.decision.is_query() {
                asked = true;
                expert_arm = e.step.response.as_ref().and_then(|r| r.expert_arm);
            }
        }
        let d = self.dim();
        let mut contexts = Vec::with_capacity(executed.len() * d);
        for e in executed {
            contexts.extend_from_slice(e.step.context.as_slice());
        }
        let contexts = Array2::from_shape_vec((executed.len(), d), contexts)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        info.set_item("asked", asked)?;
        info.set_item("expert_arm", expert_arm.map(|a: ArmId| a.0))?;
        info.set_item("item_success", executed.iter().any(|e| e.outcome.success))?;
        info.set_item(
            "executed_arms",
            executed.iter().map(|e| e.step.arm.0).collect::<Vec<_>>(),
        )?;
        info.set_item(
            "executed_rewards",
            executed
                .iter()
                .map(|e| e.outcome.reward())
                .collect::<Vec<_>>(),
        )?;
        info.set_item("executed_from_expert", from_expert(executed))?;
        info.set_item("executed_contexts", contexts.into_pyarray(py))?;
        info.set_item("wl_t", wl_after)?;
        let (obs, terminated) = match &after {
            Some(p) => {
                pending_info(&info, p)?;
                (context_array(py, &p.context), false)
            }
            None => {
                if let Some(report) = &engine.report {
                    let json = crate::convert::to_json("episode metrics", &report.metrics)?;
                    info.set_item("episode_json", json)?;
                }
                // Gymnasium wants an observation at the end too: the last
                // context the agent saw.
                (context_array(py, &before.context), true)
            }
        };
        Ok((obs, reward, before.wl_now, wl_after, terminated, info))
    }

    /// A hil policy for this environment, from its config table as JSON
    /// (e.g. `{"type": "linucb_qg", "alpha": 0.5, "w": 4.0, "pretrain":
    /// true}`), built exactly as an experiment would build it (with the
    /// environment's pretraining data); its own decisions (`Policy.act`)
    /// forecast workload with this environment's model from its WL_0.
    fn policy(&self, py: Python<'_>, policy_json: &str) -> PyResult<PyPolicyHandle> {
        let config: Box<dyn PolicyConfig> =
            crate::convert::from_json("policy config", policy_json)?;
        let policy = py
            .detach(|| config.validate().and_then(|()| config.build(&self.task)))
            .map_err(to_py_err)?;
        PyPolicyHandle::new(policy, Some(self.workload.clone()), self.settings.wl0)
            .map_err(to_py_err)
    }

    /// `policy`'s decision at the pending decision, with exactly the input
    /// the session gives its policy (this environment's workload forecast
    /// and query history): an arm, or `n_arms` to ask.
    fn act(&self, py: Python<'_>, policy: &Bound<'_, PyPolicyHandle>) -> PyResult<usize> {
        let policy = policy.get();
        self.check_policy(policy)?;
        let engine = self.engine()?;
        let Some(episode) = engine.episode.as_ref().filter(|e| e.pending().is_some()) else {
            return Err(to_py_err(HilError::state(
                "gymnasium environment",
                "no decision is pending: call reset()",
            )));
        };
        let n_arms = self.n_arms();
        py.detach(|| {
            let input = episode.pending().ok_or_else(|| {
                HilError::state("gymnasium environment", "no decision is pending")
            })?;
            Ok(match policy.state().decide(&input)?.choice {
                Choice::Act { arm } => arm.0,
                Choice::Query { .. } => n_arms,
            })
        })
        .map_err(to_py_err)
    }

    /// Teaches `policy` every attempt the last step executed, as the
    /// session loop tells its policy.
    fn learn(&self, py: Python<'_>, policy: &Bound<'_, PyPolicyHandle>) -> PyResult<()> {
        let policy = policy.get();
        self.check_policy(policy)?;
        let engine = self.engine()?;
        let executed: &[StepEvent] = &engine.executed;
        py.detach(|| {
            let mut state = policy.state();
            for (e, expert) in executed.iter().zip(from_expert(executed)) {
                state.observe(
                    &Feedback::new(Attempt {
                        context: &e.step.context,
                        arm: e.step.arm,
                        reward: e.outcome.reward(),
                        t: e.step.t,
                    })
                    .from_expert(expert),
                )?;
            }
            Ok(())
        })
        .map_err(to_py_err)
    }
}

impl GymCore {
    /// Refuses a policy for other arms or contexts than this environment's.
    fn check_policy(&self, policy: &PyPolicyHandle) -> PyResult<()> {
        let (n_arms, dim) = (self.n_arms(), self.dim());
        if policy.n_arms() != n_arms || policy.dim() != dim {
            return Err(to_py_err(HilError::invalid_input(
                "policy",
                format!(
                    "it is for {} arms and d = {}, the environment has {n_arms} arms and d = {dim}",
                    policy.n_arms(),
                    policy.dim()
                ),
            )));
        }
        Ok(())
    }

    fn build(config: GymConfig, base_dir: &str) -> hil_core::Result<Self> {
        config.session.validate()?;
        check_session_limits(&config.session)?;
        config.environment.validate()?;
        config.workload.validate()?;
        config.channel.validate()?;
        let ctx = BuildContext::new(base_dir, config.build_seed);
        let environment = config.environment.build(&ctx)?;
        let task = ctx.describe_environment(config.environment.as_ref(), environment.as_ref())?;
        let workload = config.workload.build(&ctx)?;
        let channel = config.channel.build(&task)?;
        task.action_space()
            .check(ArmId(config.fallback_arm))
            .map_err(|e| {
                HilError::invalid_parameter("fallback_arm", config.fallback_arm, e.to_string())
            })?;
        Ok(Self {
            settings: config.session,
            workload,
            kind: config.query_kind,
            fallback: ArmId(config.fallback_arm),
            environment_name: environment.name().to_string(),
            engine: Mutex::new(Engine {
                environment,
                channel,
                agent: Agent {
                    n_arms: task.action_space().len(),
                    dim: task.context_dim(),
                },
                episode: None,
                executed: Vec::new(),
                report: None,
            }),
            task,
        })
    }

    /// Starts the episode seeded by `seed` (dropping any running one) and
    /// moves it to its first decision, which it returns (`None` if the
    /// episode ended first).
    fn start(&self, engine: &mut Engine, seed: u64) -> hil_core::Result<Option<Pending>> {
        self.with_session(engine, |session, slot, executed, report| {
            *slot = None;
            *report = None;
            let mut episode = session.start_episode(seed, &mut [])?;
            *report = advance(session, &mut episode, 0, executed)?;
            executed.clear();
            let pending = Pending::of(&episode, self.kind)?;
            *slot = Some(episode);
            Ok(pending)
        })
    }

    /// Feeds `decision` to the decision awaited and moves on to the next
    /// one. Returns the decision answered and the next one (`None` when
    /// the episode has ended).
    fn feed(
        &self,
        engine: &mut Engine,
        decision: Decision,
    ) -> hil_core::Result<(Pending, Option<Pending>)> {
        self.with_session(engine, |session, slot, executed, report| {
            let ended = || {
                HilError::state(
                    "gymnasium environment",
                    "the episode has ended: call reset()",
                )
            };
            let episode = slot.as_mut().ok_or_else(ended)?;
            let before = Pending::of(episode, self.kind)?.ok_or_else(ended)?;
            let from = episode.events().len();
            session.feed_decision(episode, decision, &mut [])?;
            *report = advance(session, episode, from, executed)?;
            Ok((before, Pending::of(episode, self.kind)?))
        })
    }
}

/// For each executed attempt, whether its arm came from the expert (the
/// session's `Feedback::from_expert`): from an answered query on, every
/// attempt at the item executes the expert's arm.
fn from_expert(executed: &[StepEvent]) -> Vec<bool> {
    let mut answered = false;
    executed
        .iter()
        .map(|e| {
            if e.step.decision.is_query() {
                answered = e
                    .step
                    .response
                    .as_ref()
                    .is_some_and(|r| r.expert_arm.is_some());
            }
            answered
        })
        .collect()
}

fn pending_info(info: &Bound<'_, PyDict>, p: &Pending) -> PyResult<()> {
    info.set_item("t", p.t)?;
    info.set_item("item_index", p.item_index)?;
    info.set_item("item_label", &p.item_label)?;
    info.set_item("items_seen", p.items_seen)?;
    info.set_item("attempt", p.attempt)?;
    info.set_item("workload", p.wl_now)?;
    info.set_item("workload_if_ask", p.wl_if_ask)?;
    info.set_item("n_queries", p.n_queries)?;
    Ok(())
}

/// The paper's food split (`hil_envs::FoodSplit::paper`) as JSON: keys
/// `pretrain`, `validation`, `test`, each a list of food names.
#[pyfunction]
fn paper_food_split_json() -> PyResult<String> {
    crate::convert::to_json("the paper's food split", &hil_envs::FoodSplit::paper())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GymCore>()?;
    m.add_function(wrap_pyfunction!(paper_food_split_json, m)?)?;
    Ok(())
}
