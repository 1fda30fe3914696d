//! Hyperparameter selection on validation, evaluation on test, and the
//! aggregated results of a protocol run.

use hil_core::metrics::mean_std;
use hil_core::{HilError, Result};
use serde::{Deserialize, Serialize};

use crate::protocol::{Family, NamedModel, Phase, PolicySpec, ProtocolSettings, RunRecord, Scored};

/// Mean and (population) standard deviation over runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
}

impl Stat {
    fn of(xs: &[f64]) -> Self {
        let (mean, std) = mean_std(xs);
        Self { mean, std }
    }
}

/// A tuned hyperparameter and its value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hyperparameter {
    /// `w` (LinUCB-QG) or `c` (LinUCB-ExpDecay).
    pub name: String,
    /// The chosen value.
    pub value: f64,
}

/// Test metrics of one policy under one model and w_task.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricSummary {
    /// Runs aggregated (seeds × policy seeds).
    pub n_runs: usize,
    /// r_task_avg.
    pub r_task_avg: Stat,
    /// ΔWL = f(WL_0, Q_T) − WL_0 at the final step (the paper's definition).
    pub delta_wl: Stat,
    /// M_wt.
    pub m_wt: Stat,
    /// t_conv.
    pub t_conv: Stat,
    /// f_q.
    pub f_q: Stat,
    /// f_fail_food.
    pub f_fail_food: Stat,
    /// f_auto_food.
    pub f_auto_food: Stat,
}

impl MetricSummary {
    fn of(scored: &[Scored]) -> Self {
        let col = |f: fn(&Scored) -> f64| Stat::of(&scored.iter().map(f).collect::<Vec<_>>());
        Self {
            n_runs: scored.len(),
            r_task_avg: col(|s| s.r_task_avg),
            delta_wl: col(|s| s.delta_wl),
            m_wt: col(|s| s.m_wt),
            t_conv: col(|s| s.t_conv),
            f_q: col(|s| s.f_q),
            f_fail_food: col(|s| s.f_fail_food),
            f_auto_food: col(|s| s.f_auto_food),
        }
    }
}

/// One row of the results: (workload model, w_task, policy).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultRow {
    /// The model the policy decided with and was scored with.
    pub model: String,
    /// w_task.
    pub w_task: f64,
    /// The policy.
    pub policy: Family,
    /// The hyperparameter chosen on validation, if the policy has one.
    pub selected: Option<Hyperparameter>,
    /// Test metrics.
    pub test: MetricSummary,
}

/// How a hyperparameter was chosen: validation M_wt of every candidate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SelectionRow {
    /// Model.
    pub model: String,
    /// w_task.
    pub w_task: f64,
    /// Policy.
    pub policy: Family,
    /// (value, mean validation M_wt) per candidate, in grid order.
    pub candidates: Vec<(f64, f64)>,
    /// The chosen value (the first maximiser).
    pub chosen: f64,
}

/// LinUCB-QG deciding with one model and scored with another.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossRow {
    /// Decision model.
    pub decide: String,
    /// Scoring model.
    pub score: String,
    /// w_task.
    pub w_task: f64,
    /// w chosen on validation with the decision model.
    pub selected: Hyperparameter,
    /// Test metrics scored with `score`.
    pub test: MetricSummary,
}

/// Everything a protocol run produced, ready to serialise.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProtocolResults {
    /// Where the data came from.
    pub provenance: String,
    /// Settings used.
    pub settings: ProtocolSettings,
    /// Workload model names, in order.
    pub models: Vec<String>,
    /// Episodes run.
    pub n_episodes: usize,
    /// Main rows.
    pub rows: Vec<ResultRow>,
    /// Cross-data rows.
    pub cross: Vec<CrossRow>,
    /// Hyperparameter selection details.
    pub selection: Vec<SelectionRow>,
}

impl ProtocolResults {
    /// The row for (model, w_task, policy), if computed.
    pub fn row(&self, model: &str, w_task: f64, policy: Family) -> Option<&ResultRow> {
        self.rows
            .iter()
            .find(|r| r.model == model && (r.w_task - w_task).abs() < 1e-9 && r.policy == policy)
    }
}

struct Index<'a> {
    records: &'a [RunRecord],
}

impl<'a> Index<'a> {
    fn runs(&self, phase: Phase, spec: &PolicySpec, decide: Option<usize>) -> Vec<&'a RunRecord> {
        self.records
            .iter()
            .filter(|r| r.key.phase == phase && r.key.spec == *spec && r.key.decide_model == decide)
            .collect()
    }
}

fn score_all(
    runs: &[&RunRecord],
    model: &NamedModel,
    wl0: f64,
    w_task: f64,
) -> Result<Vec<Scored>> {
    runs.iter()
        .map(|r| r.score(model.model.as_ref(), wl0, w_task))
        .collect()
}

/// A policy spec with the index of the model it decides with (QG only).
type Candidate = (PolicySpec, Option<usize>);

/// Candidates of `family` when the decision model is `m`.
fn candidates(s: &ProtocolSettings, family: Family, m: usize) -> Vec<Candidate> {
    match family {
        Family::Linucb => vec![(PolicySpec::Linucb, None)],
        Family::AlwaysQuery => vec![(PolicySpec::AlwaysQuery, None)],
        Family::LinucbExpDecay => s
            .exp_decay_c
            .iter()
            .map(|&c| (PolicySpec::LinucbExpDecay { c }, None))
            .collect(),
        Family::LinucbQg => s
            .qg_w
            .iter()
            .map(|&w| (PolicySpec::LinucbQg { w }, Some(m)))
            .collect(),
    }
}

/// Chooses, by mean validation M_wt under `models[m]`, among `family`'s candidates.
fn select(
    s: &ProtocolSettings,
    idx: &Index<'_>,
    models: &[NamedModel],
    m: usize,
    family: Family,
    w_task: f64,
) -> Result<(Candidate, Vec<(f64, f64)>)> {
    let mut best: Option<(Candidate, f64)> = None;
    let mut table = Vec::new();
    for cand in candidates(s, family, m) {
        let runs = idx.runs(Phase::Validation, &cand.0, cand.1);
        if runs.is_empty() {
            return Err(HilError::state(
                "protocol",
                format!("no validation runs of {:?}", cand.0),
            ));
        }
        let scored = score_all(&runs, &models[m], s.session.wl0, w_task)?;
        let mean = scored.iter().map(|x| x.m_wt).sum::<f64>() / scored.len() as f64;
        table.push((cand.0.hyperparameter().map_or(0.0, |h| h.1), mean));
        if best.as_ref().is_none_or(|(_, b)| mean > *b) {
            best = Some((cand, mean));
        }
    }
    let (chosen, _) = best.ok_or_else(|| HilError::state("protocol", "empty grid"))?;
    Ok((chosen, table))
}

/// Selects hyperparameters on validation and aggregates test metrics.
pub fn aggregate(
    settings: &ProtocolSettings,
    models: &[NamedModel],
    records: &[RunRecord],
    provenance: &str,
) -> Result<ProtocolResults> {
    let idx = Index { records };
    let wl0 = settings.session.wl0;
    let mut rows = Vec::new();
    let mut selection = Vec::new();
    for (m, model) in models.iter().enumerate() {
        for &w_task in &settings.w_tasks {
            for family in Family::ALL {
                let ((spec, decide), table) = select(settings, &idx, models, m, family, w_task)?;
                let runs = idx.runs(Phase::Test, &spec, decide);
                let test = MetricSummary::of(&score_all(&runs, model, wl0, w_task)?);
                let selected = spec.hyperparameter().map(|(n, v)| Hyperparameter {
                    name: n.into(),
                    value: v,
                });
                if let Some(h) = &selected {
                    selection.push(SelectionRow {
                        model: model.name.clone(),
                        w_task,
                        policy: family,
                        candidates: table,
                        chosen: h.value,
                    });
                }
                rows.push(ResultRow {
                    model: model.name.clone(),
                    w_task,
                    policy: family,
                    selected,
                    test,
                });
            }
        }
    }
    let mut cross = Vec::new();
    for c in &settings.cross {
        let find = |n: &str| {
            models
                .iter()
                .position(|m| m.name == n)
                .ok_or_else(|| HilError::invalid_parameter("cross", n, "unknown workload model"))
        };
        let (d, sc) = (find(&c.decide)?, find(&c.score)?);
        let w_task = settings.cross_w_task;
        let ((spec, decide), _) = select(settings, &idx, models, d, Family::LinucbQg, w_task)?;
        let runs = idx.runs(Phase::Test, &spec, decide);
        let test = MetricSummary::of(&score_all(&runs, &models[sc], wl0, w_task)?);
        let (n, v) = spec.hyperparameter().expect("QG has w");
        cross.push(CrossRow {
            decide: c.decide.clone(),
            score: c.score.clone(),
            w_task,
            selected: Hyperparameter {
                name: n.into(),
                value: v,
            },
            test,
        });
    }
    Ok(ProtocolResults {
        provenance: provenance.to_string(),
        settings: settings.clone(),
        models: models.iter().map(|m| m.name.clone()).collect(),
        n_episodes: records.len(),
        rows,
        cross,
        selection,
    })
}
