//! The paper's simulated-testbed protocol.
//!
//! 1. Split the foods (pretrain / validation / test, [`FoodSplit`]). The
//!    caller pretrains the LinUCB estimator once on the pretraining foods and
//!    hands a [`PolicyFactory`] that clones it into fresh policies.
//! 2. Run every (phase, policy, hyperparameter, seed[, policy seed][,
//!    decision workload model]) episode once, in parallel. Policies whose
//!    decisions do not use the workload model (LinUCB, AlwaysQuery,
//!    LinUCB-ExpDecay) run once and are scored under every model; LinUCB-QG
//!    runs once per decision model. w_task never changes a run, only how it
//!    is scored, so no run is repeated per w_task.
//! 3. For every scoring model and w_task, choose each tunable policy's
//!    hyperparameter (w for QG, c for ExpDecay) maximising the mean M_wt
//!    over the validation runs, then report test metrics of that choice.
//! 4. Cross-data: QG deciding with one model and scored with another, its w
//!    chosen on validation with the deciding model (as the paper's numbers
//!    show: its cross-data r_task and f_q equal the same-model rows).
//!
//! **ΔWL definition.** The paper scores WL_T = f(WL_0, Q_T) evaluated at the
//! episode's final timestep T over the whole query history (so a policy that
//! never queries gets ΔWL = f(WL_0, ∅) − WL_0, e.g. −0.5 for a model that
//! predicts 0 without queries). hil-core's session tracks a workload state
//! that changes only at query steps (its `EpisodeMetrics::delta_wl` is 0
//! without queries). The tables use the paper's definition,
//! [`paper_delta_wl`], everywhere.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use hil_core::session::splitmix;
use hil_core::{
    ArmId, Context, Decision, DecisionInput, Environment, EpisodeMetrics, Feedback, HilError, Item,
    Outcome, Policy, Query, QueryChannel, QueryHistory, Response, Result, Session, SessionSettings,
    StepDecision, Timestep, WorkloadModel,
};
use serde::{Deserialize, Serialize};

use crate::dataset::FoodDataset;
use crate::env::DatasetReplayEnv;
use crate::split::FoodSplit;

/// The four algorithms of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// Fully autonomous LinUCB.
    Linucb,
    /// Always asks.
    AlwaysQuery,
    /// LinUCB asking with probability e^{−cN} at an item's first attempt.
    LinucbExpDecay,
    /// LinUCB-QG: asks when the gap G exceeds w·WL_t.
    LinucbQg,
}

impl Family {
    /// All four, in the paper's table order.
    pub const ALL: [Family; 4] = [
        Family::Linucb,
        Family::AlwaysQuery,
        Family::LinucbExpDecay,
        Family::LinucbQg,
    ];

    /// The name the paper prints.
    pub fn display(self) -> &'static str {
        match self {
            Family::Linucb => "LinUCB",
            Family::AlwaysQuery => "AlwaysQuery",
            Family::LinucbExpDecay => "LinUCB-ExpDecay",
            Family::LinucbQg => "LinUCB-QG",
        }
    }

    /// The policy's config name (`type = "..."`).
    pub fn config_name(self) -> &'static str {
        match self {
            Family::Linucb => "linucb",
            Family::AlwaysQuery => "always_query",
            Family::LinucbExpDecay => "linucb_exp_decay",
            Family::LinucbQg => "linucb_qg",
        }
    }
}

/// One policy with its hyperparameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum PolicySpec {
    /// LinUCB.
    Linucb,
    /// AlwaysQuery.
    AlwaysQuery,
    /// LinUCB-ExpDecay with decay rate `c`.
    LinucbExpDecay {
        /// Decay rate c.
        c: f64,
    },
    /// LinUCB-QG with scaling factor `w`.
    LinucbQg {
        /// Scaling factor w.
        w: f64,
    },
}

impl PolicySpec {
    /// The algorithm.
    pub fn family(&self) -> Family {
        match self {
            PolicySpec::Linucb => Family::Linucb,
            PolicySpec::AlwaysQuery => Family::AlwaysQuery,
            PolicySpec::LinucbExpDecay { .. } => Family::LinucbExpDecay,
            PolicySpec::LinucbQg { .. } => Family::LinucbQg,
        }
    }

    /// The tuned hyperparameter, as (name, value).
    pub fn hyperparameter(&self) -> Option<(&'static str, f64)> {
        match self {
            PolicySpec::LinucbExpDecay { c } => Some(("c", *c)),
            PolicySpec::LinucbQg { w } => Some(("w", *w)),
            _ => None,
        }
    }

    /// Whether decisions depend on the workload model.
    pub fn uses_workload(&self) -> bool {
        matches!(self, PolicySpec::LinucbQg { .. })
    }

    /// Whether decisions depend on the policy's own random seed.
    pub fn stochastic(&self) -> bool {
        matches!(self, PolicySpec::LinucbExpDecay { .. })
    }
}

/// Builds fresh policies for the protocol (typically cloning one pretrained
/// estimator). Implemented by the caller, who knows the policy crate.
pub trait PolicyFactory: Sync {
    /// A fresh policy for `spec`, built for the dataset's arms and dimension.
    fn build(&self, spec: &PolicySpec) -> Result<Box<dyn Policy>>;
}

impl<F: Fn(&PolicySpec) -> Result<Box<dyn Policy>> + Sync> PolicyFactory for F {
    fn build(&self, spec: &PolicySpec) -> Result<Box<dyn Policy>> {
        self(spec)
    }
}

/// A workload model with the name it is reported under.
#[derive(Clone)]
pub struct NamedModel {
    /// Name, e.g. `f1_sim`.
    pub name: String,
    /// The model.
    pub model: Arc<dyn WorkloadModel>,
}

impl std::fmt::Debug for NamedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NamedModel")
            .field("name", &self.name)
            .finish()
    }
}

/// A cross-data setting: decide with one model, score with another.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrossSetting {
    /// The model LinUCB-QG decides with.
    pub decide: String,
    /// The model ΔWL and M_wt are computed with.
    pub score: String,
}

/// Everything that defines a protocol run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProtocolSettings {
    /// Food split.
    pub split: FoodSplit,
    /// N_att and WL_0.
    pub session: SessionSettings,
    /// Items per episode.
    pub items_per_episode: usize,
    /// Master seed; environment and policy seeds derive from it.
    pub seed: u64,
    /// Number of environment seeds (episodes per configuration).
    pub n_seeds: usize,
    /// Policy seeds for stochastic policies (LinUCB-ExpDecay).
    pub n_policy_seeds: usize,
    /// The w_task values scored.
    pub w_tasks: Vec<f64>,
    /// Grid of LinUCB-QG's w.
    pub qg_w: Vec<f64>,
    /// Grid of LinUCB-ExpDecay's c.
    pub exp_decay_c: Vec<f64>,
    /// Cross-data settings.
    pub cross: Vec<CrossSetting>,
    /// w_task of the cross-data experiment.
    pub cross_w_task: f64,
}

impl ProtocolSettings {
    /// The paper's protocol: 3 seeds, 5 policy seeds, N_att = 10,
    /// WL_0 = 0.5, 5 items per episode, w_task ∈ {0.2, …, 0.9}, f1-on-f2
    /// and f12-on-f2 at w_task = 0.4. The w and c grids are ours (the paper
    /// does not list them).
    pub fn paper() -> Self {
        Self {
            split: FoodSplit::paper(),
            session: SessionSettings::default(),
            items_per_episode: 5,
            seed: 0,
            n_seeds: 3,
            n_policy_seeds: 5,
            w_tasks: (2..=9).map(|k| k as f64 / 10.0).collect(),
            qg_w: vec![0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0],
            exp_decay_c: vec![0.0, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0],
            cross: vec![
                CrossSetting {
                    decide: "f1_sim".into(),
                    score: "f2_sim".into(),
                },
                CrossSetting {
                    decide: "f12_sim".into(),
                    score: "f2_sim".into(),
                },
            ],
            cross_w_task: 0.4,
        }
    }

    /// A fast smoke version: smaller grids, 2 policy seeds.
    pub fn quick() -> Self {
        Self {
            n_policy_seeds: 2,
            qg_w: vec![0.5, 4.0, 32.0],
            exp_decay_c: vec![0.0, 0.5, 4.0],
            ..Self::paper()
        }
    }

    /// Checks the settings against a dataset and the available models.
    pub fn validate(&self, ds: &FoodDataset, models: &[NamedModel]) -> Result<()> {
        self.split.validate(ds)?;
        self.session.validate()?;
        let positive = |name: &str, v: usize| {
            if v == 0 {
                Err(HilError::invalid_parameter(name, 0, "must be at least 1"))
            } else {
                Ok(())
            }
        };
        positive("items_per_episode", self.items_per_episode)?;
        positive("n_seeds", self.n_seeds)?;
        positive("n_policy_seeds", self.n_policy_seeds)?;
        for (name, v) in [("w_tasks", &self.w_tasks)] {
            if v.is_empty() || v.iter().any(|w| !(0.0..=1.0).contains(w)) {
                return Err(HilError::invalid_parameter(
                    name,
                    format!("{v:?}"),
                    "needs at least one value, each in [0, 1]",
                ));
            }
        }
        for (name, v) in [("qg_w", &self.qg_w), ("exp_decay_c", &self.exp_decay_c)] {
            if v.is_empty() || v.iter().any(|x| !x.is_finite() || *x < 0.0) {
                return Err(HilError::invalid_parameter(
                    name,
                    format!("{v:?}"),
                    "needs at least one value, each finite and >= 0",
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.cross_w_task) {
            return Err(HilError::invalid_parameter(
                "cross_w_task",
                self.cross_w_task,
                "must be in [0, 1]",
            ));
        }
        if models.is_empty() {
            return Err(HilError::invalid_input("workload models", "none given"));
        }
        for c in &self.cross {
            for n in [&c.decide, &c.score] {
                if !models.iter().any(|m| &m.name == n) {
                    return Err(HilError::invalid_parameter(
                        "cross",
                        n,
                        "no workload model of that name is in the protocol",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Environment seed `i`.
    pub fn env_seed(&self, i: usize) -> u64 {
        splitmix(self.seed, 100 + i as u64)
    }

    /// Policy seed `j`.
    pub fn policy_seed(&self, j: usize) -> u64 {
        splitmix(self.seed, 200 + j as u64)
    }
}

/// Validation or test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Hyperparameters are chosen here.
    Validation,
    /// Chosen hyperparameters are evaluated here.
    Test,
}

/// Identifies one episode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunKey {
    /// Phase.
    pub phase: Phase,
    /// Policy and hyperparameter.
    pub spec: PolicySpec,
    /// Index of the model the policy decides with (QG only).
    pub decide_model: Option<usize>,
    /// Environment seed index.
    pub seed: usize,
    /// Policy seed index (0 for deterministic policies).
    pub policy_seed: usize,
}

/// What one step of a run looked like (enough for metrics and plots).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepTrace {
    /// Timestep.
    pub t: Timestep,
    /// Item index.
    pub item_index: usize,
    /// The item's food.
    pub food: String,
    /// A query was asked at this step.
    pub query: bool,
    /// The gap G, if the policy reported it.
    pub gap: Option<f64>,
    /// The threshold G was compared with, if reported.
    pub threshold: Option<f64>,
    /// The attempt succeeded.
    pub success: bool,
}

/// One finished episode.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunRecord {
    /// Which episode.
    pub key: RunKey,
    /// Metrics from hil-core (its `delta_wl` is the session's tracked one;
    /// tables use [`paper_delta_wl`]).
    pub metrics: EpisodeMetrics,
    /// Queries asked.
    pub queries: QueryHistory,
    /// Final timestep T.
    pub t_final: Timestep,
    /// Every step.
    pub steps: Vec<StepTrace>,
}

/// The paper's ΔWL = f(WL_0, Q_T; θ) − WL_0 at the final timestep T.
///
/// ```
/// use hil_core::{QueryHistory, QueryKind, testing::fixtures::CountingWorkload};
/// let mut q = QueryHistory::new();
/// q.push(3, QueryKind::default()).unwrap();
/// let d = hil_envs::protocol::paper_delta_wl(&CountingWorkload::new(0.1), 0.5, &q, 9).unwrap();
/// assert!((d - 0.1).abs() < 1e-12);
/// ```
pub fn paper_delta_wl(
    model: &dyn WorkloadModel,
    wl0: f64,
    queries: &QueryHistory,
    t_final: Timestep,
) -> Result<f64> {
    let wl = model.predict(wl0, queries, t_final)?;
    if !wl.is_finite() {
        return Err(HilError::invalid_input(
            format!("workload prediction of `{}`", model.name()),
            format!("{wl} is not finite"),
        ));
    }
    Ok(wl - wl0)
}

/// Metrics of one run under one scoring model and w_task.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    /// r_task_avg.
    pub r_task_avg: f64,
    /// ΔWL (paper definition).
    pub delta_wl: f64,
    /// M_wt.
    pub m_wt: f64,
    /// t_conv.
    pub t_conv: f64,
    /// f_q.
    pub f_q: f64,
    /// f_fail_food.
    pub f_fail_food: f64,
    /// f_auto_food.
    pub f_auto_food: f64,
}

impl RunRecord {
    /// Scores this run with `model` at `w_task`.
    pub fn score(&self, model: &dyn WorkloadModel, wl0: f64, w_task: f64) -> Result<Scored> {
        let m = &self.metrics;
        let delta_wl = paper_delta_wl(model, wl0, &self.queries, self.t_final)?;
        Ok(Scored {
            r_task_avg: m.r_task_avg,
            delta_wl,
            m_wt: w_task * m.r_task_avg - (1.0 - w_task) * delta_wl,
            t_conv: m.t_conv,
            f_q: m.f_q,
            f_fail_food: m.f_fail_food,
            f_auto_food: m.f_auto_food,
        })
    }

    /// WL_t under `model` at every timestep 0..=T (the curve the paper plots).
    pub fn workload_curve(&self, model: &dyn WorkloadModel, wl0: f64) -> Result<Vec<f64>> {
        (0..=self.t_final)
            .map(|t| {
                if t == 0 {
                    Ok(wl0)
                } else {
                    model.predict(wl0, &self.queries, t)
                }
            })
            .collect()
    }
}

/// The paper's simulated expert: answers every query with the
/// environment's best action argmax_a s(x, a).
#[derive(Clone, Copy, Debug, Default)]
pub struct PerfectExpert;

impl QueryChannel for PerfectExpert {
    fn name(&self) -> &str {
        "perfect_expert"
    }
    fn ask(&mut self, query: &Query) -> Result<Response> {
        let arm = query.oracle_best.ok_or_else(|| HilError::Channel {
            channel: "perfect_expert".into(),
            why: "the environment does not know its best action".into(),
        })?;
        Ok(Response::action(arm))
    }
}

/// Decouples the environment seed from the session seed (the session derives
/// both environment and policy seeds from one number; the protocol crosses
/// 3 environment seeds with 5 policy seeds).
struct FixedEnvSeed {
    inner: DatasetReplayEnv,
    seed: u64,
}

impl Environment for FixedEnvSeed {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn action_space(&self) -> &hil_core::ActionSpace {
        self.inner.action_space()
    }
    fn context_dim(&self) -> usize {
        self.inner.context_dim()
    }
    fn reset(&mut self, _seed: u64) -> Result<()> {
        self.inner.reset(self.seed)
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        self.inner.next_item()
    }
    fn observe(&mut self) -> Result<Context> {
        self.inner.observe()
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.inner.execute(arm)
    }
    fn best_action(&self) -> Option<ArmId> {
        self.inner.best_action()
    }
    fn current_item(&self) -> Option<&Item> {
        self.inner.current_item()
    }
}

/// Same, for the policy's seed.
struct FixedPolicySeed {
    inner: Box<dyn Policy>,
    seed: u64,
}

impl Policy for FixedPolicySeed {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn n_arms(&self) -> usize {
        self.inner.n_arms()
    }
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn seed(&mut self, _seed: u64) {
        self.inner.seed(self.seed)
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        self.inner.decide(input)
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        self.inner.observe(feedback)
    }
}

/// The protocol, ready to run.
pub struct Protocol<'a> {
    /// Settings.
    pub settings: ProtocolSettings,
    /// The dataset.
    pub dataset: Arc<FoodDataset>,
    /// Workload models (decision and scoring).
    pub models: Vec<NamedModel>,
    /// Builds policies.
    pub factory: &'a dyn PolicyFactory,
}

impl std::fmt::Debug for Protocol<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Protocol")
            .field("settings", &self.settings)
            .field("dataset", &self.dataset.name)
            .field("models", &self.models)
            .finish()
    }
}

impl Protocol<'_> {
    /// Every episode the protocol needs, each exactly once.
    pub fn jobs(&self) -> Vec<RunKey> {
        let s = &self.settings;
        let mut specs: Vec<(PolicySpec, Option<usize>, usize)> = vec![
            (PolicySpec::Linucb, None, 1),
            (PolicySpec::AlwaysQuery, None, 1),
        ];
        for &c in &s.exp_decay_c {
            specs.push((PolicySpec::LinucbExpDecay { c }, None, s.n_policy_seeds));
        }
        for m in 0..self.models.len() {
            for &w in &s.qg_w {
                specs.push((PolicySpec::LinucbQg { w }, Some(m), 1));
            }
        }
        let mut jobs = Vec::new();
        for phase in [Phase::Validation, Phase::Test] {
            for &(spec, decide_model, n_ps) in &specs {
                for seed in 0..s.n_seeds {
                    for policy_seed in 0..n_ps {
                        jobs.push(RunKey {
                            phase,
                            spec,
                            decide_model,
                            seed,
                            policy_seed,
                        });
                    }
                }
            }
        }
        jobs
    }

    /// Runs one episode.
    pub fn run_one(&self, key: &RunKey) -> Result<RunRecord> {
        let s = &self.settings;
        let foods = match key.phase {
            Phase::Validation => &s.split.validation,
            Phase::Test => &s.split.test,
        };
        let env = DatasetReplayEnv::new(self.dataset.clone(), foods, s.items_per_episode)?;
        let mut env = FixedEnvSeed {
            inner: env,
            seed: s.env_seed(key.seed),
        };
        let mut policy = FixedPolicySeed {
            inner: self.factory.build(&key.spec)?,
            seed: s.policy_seed(key.policy_seed),
        };
        let mut channel = PerfectExpert;
        // Policies that ignore workload are tracked with the first model; the
        // tables rescore every run with each model anyway.
        let model = self.models[key.decide_model.unwrap_or(0)].model.clone();
        let mut session = Session {
            settings: s.session.clone(),
            environment: &mut env,
            policy: &mut policy,
            channel: &mut channel,
            workload: model,
            forecast: None,
        };
        let session_seed = splitmix(s.env_seed(key.seed), key.policy_seed as u64);
        let report = session.run_episode(session_seed, &mut [])?;
        let mut queries = QueryHistory::new();
        let mut steps = Vec::with_capacity(report.events.len());
        for e in &report.events {
            let st = &e.step;
            if let StepDecision::Query { kind, .. } = st.decision {
                queries.push(st.t, kind)?;
            }
            steps.push(StepTrace {
                t: st.t,
                item_index: st.item_index,
                food: st.item_label.clone(),
                query: st.decision.is_query(),
                gap: st.diagnostics.as_ref().and_then(|d| d.gap),
                threshold: st.diagnostics.as_ref().and_then(|d| d.threshold),
                success: e.outcome.success,
            });
        }
        Ok(RunRecord {
            key: *key,
            t_final: report.events.last().map_or(0, |e| e.step.t),
            metrics: report.metrics,
            queries,
            steps,
        })
    }

    /// Runs every job on `threads` worker threads, calling `progress(done,
    /// total)` after each, and returns the records in job order.
    pub fn run_all(
        &self,
        threads: usize,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Vec<RunRecord>> {
        self.settings.validate(&self.dataset, &self.models)?;
        let jobs = self.jobs();
        let total = jobs.len();
        let next = AtomicUsize::new(0);
        let done = AtomicUsize::new(0);
        let failed = AtomicBool::new(false);
        let results: Mutex<Vec<Option<Result<RunRecord>>>> =
            Mutex::new((0..total).map(|_| None).collect());
        std::thread::scope(|scope| {
            for _ in 0..threads.max(1) {
                scope.spawn(|| {
                    loop {
                        if failed.load(Ordering::Relaxed) {
                            break;
                        }
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= total {
                            break;
                        }
                        let r = self.run_one(&jobs[i]);
                        if r.is_err() {
                            failed.store(true, Ordering::Relaxed);
                        }
                        results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(r);
                        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    }
                });
            }
        });
        let results = results.into_inner().unwrap_or_else(|e| e.into_inner());
        let mut out = Vec::with_capacity(total);
        for (r, key) in results.into_iter().zip(&jobs) {
            match r {
                Some(Ok(rec)) => out.push(rec),
                Some(Err(e)) => {
                    return Err(HilError::state(
                        "protocol",
                        format!("run {key:?} failed: {e}"),
                    ));
                }
                None => {}
            }
        }
        if out.len() != total {
            return Err(HilError::state("protocol", "a run failed; see above"));
        }
        Ok(out)
    }
}
