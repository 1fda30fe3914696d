//! Hyperparameter selection on validation, evaluation on test, and the
//! aggregated results of a protocol run.

use hil_core::{HilError, Result};
use hil_stats::{Stat, mean};
use serde::{Deserialize, Serialize};

use hil_core::EpisodeMetrics;

use crate::method::GridPoint;
use crate::testbed::{NamedModel, Phase, ProtocolSettings, RunRecord};

/// Which spread a table reports after ±.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Spread {
    /// Population standard deviation over runs (the paper's tables).
    Std,
    /// Standard error of the mean.
    Se,
}

impl Spread {
    /// The spread of `stat` this one names.
    pub fn of(self, stat: Stat) -> f64 {
        match self {
            Self::Std => stat.std,
            Self::Se => stat.se,
        }
    }
}

/// A tuned hyperparameter and its value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hyperparameter {
    /// Its name in the policy config (`w` for LinUCB-QG, `c` for LinUCB-ExpDecay).
    pub name: String,
    /// The chosen value.
    pub value: f64,
}

impl Hyperparameter {
    fn of(point: &GridPoint) -> Option<Self> {
        point.as_ref().map(|(name, value)| Self {
            name: name.clone(),
            value: *value,
        })
    }
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
    /// Summarises episodes scored at `w_task`.
    pub fn of(scored: &[EpisodeMetrics], w_task: f64) -> Self {
        let col = |f: &dyn Fn(&EpisodeMetrics) -> f64| {
            Stat::of(&scored.iter().map(f).collect::<Vec<_>>())
        };
        Self {
            n_runs: scored.len(),
            r_task_avg: col(&|s| s.r_task_avg),
            delta_wl: col(&|s| s.delta_wl),
            m_wt: col(&|s| s.m_wt(w_task)),
            t_conv: col(&|s| s.t_conv),
            f_q: col(&|s| s.f_q),
            f_fail_food: col(&|s| s.f_fail_food),
            f_auto_food: col(&|s| s.f_auto_food),
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
    /// The method's label.
    pub method: String,
    /// The hyperparameter chosen on validation, if the method is tuned.
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
    /// The method's label.
    pub method: String,
    /// (value, mean validation M_wt) per candidate, in grid order.
    pub candidates: Vec<(f64, f64)>,
    /// The chosen value (the first maximiser).
    pub chosen: f64,
}

/// A method deciding with one model and scored with another.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossRow {
    /// The method's label.
    pub method: String,
    /// Decision model.
    pub decide: String,
    /// Scoring model.
    pub score: String,
    /// w_task.
    pub w_task: f64,
    /// The hyperparameter chosen on validation with the decision model.
    pub selected: Option<Hyperparameter>,
    /// Test metrics scored with `score`.
    pub test: MetricSummary,
}

/// Everything a protocol run produced, ready to serialise.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProtocolResults {
    /// Where the data came from.
    pub provenance: String,
    /// Environment seeds aggregated (the first `n_env_seeds` of the run).
    pub n_env_seeds: usize,
    /// The spread the tables report: the paper protocol's population std,
    /// or the many-seed run's standard error.
    pub spread: Spread,
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
    /// The row for (model, w_task, method label), if computed.
    pub fn row(&self, model: &str, w_task: f64, method: &str) -> Option<&ResultRow> {
        self.rows
            .iter()
            .find(|r| r.model == model && (r.w_task - w_task).abs() < 1e-9 && r.method == method)
    }
}

struct Index<'a> {
    records: Vec<&'a RunRecord>,
}

impl<'a> Index<'a> {
    fn runs(&self, phase: Phase, method: usize, cand: &Candidate) -> Vec<&'a RunRecord> {
        self.records
            .iter()
            .filter(|r| {
                r.key.phase == phase
                    && r.key.method == method
                    && r.key.point == cand.0
                    && r.key.decide_model == cand.1
            })
            .copied()
            .collect()
    }
}

/// Every run scored under `model` (hil-core's definition, rescored).
fn score_all(runs: &[&RunRecord], model: &NamedModel) -> Result<Vec<EpisodeMetrics>> {
    runs.iter()
        .map(|r| r.metrics.rescored(model.model.as_ref()))
        .collect()
}

/// A grid point with the index of the model the method decides with.
type Candidate = (GridPoint, Option<usize>);

/// Candidates of method `i` when the decision model is `m`: one per grid
/// point, deciding with `m` if the method has runs per deciding model.
fn candidates(idx: &Index<'_>, s: &ProtocolSettings, i: usize, m: usize) -> Vec<Candidate> {
    candidates_at(idx, s.methods[i].grid(), i, m)
}

/// [`candidates`] at the grid points `points` of method `i`.
fn candidates_at(idx: &Index<'_>, points: Vec<GridPoint>, i: usize, m: usize) -> Vec<Candidate> {
    points
        .into_iter()
        .map(|point| {
            let per_model = idx
                .records
                .iter()
                .any(|r| r.key.method == i && r.key.point == point && r.key.decide_model.is_some());
            (point, per_model.then_some(m))
        })
        .collect()
}

/// Chooses, by mean validation M_wt under `models[m]`, among method `i`'s
/// candidates.
fn select(
    s: &ProtocolSettings,
    idx: &Index<'_>,
    models: &[NamedModel],
    m: usize,
    i: usize,
    w_task: f64,
) -> Result<(Candidate, Vec<(f64, f64)>)> {
    let mut best: Option<(Candidate, f64)> = None;
    let mut table = Vec::new();
    for cand in candidates(idx, s, i, m) {
        let runs = idx.runs(Phase::Validation, i, &cand);
        if runs.is_empty() {
            return Err(HilError::state(
                "protocol",
                format!(
                    "no validation runs of `{}` {:?}",
                    s.methods[i].label, cand.0
                ),
            ));
        }
        let scored = score_all(&runs, &models[m])?;
        let m_wt = mean(&scored.iter().map(|x| x.m_wt(w_task)).collect::<Vec<_>>());
        table.push((cand.0.as_ref().map_or(0.0, |h| h.1), m_wt));
        if best.as_ref().is_none_or(|(_, b)| m_wt > *b) {
            best = Some((cand, m_wt));
        }
    }
    let (chosen, _) = best.ok_or_else(|| HilError::state("protocol", "empty grid"))?;
    Ok((chosen, table))
}

/// Selects hyperparameters on validation and aggregates test metrics over
/// the first `n_env_seeds` environment seeds of `records`, reporting
/// `spread` after ±.
pub fn aggregate(
    settings: &ProtocolSettings,
    models: &[NamedModel],
    records: &[RunRecord],
    provenance: &str,
    n_env_seeds: usize,
    spread: Spread,
) -> Result<ProtocolResults> {
    let idx = Index {
        records: records
            .iter()
            .filter(|r| r.key.seed < n_env_seeds)
            .collect(),
    };
    let mut rows = Vec::new();
    let mut selection = Vec::new();
    for (m, model) in models.iter().enumerate() {
        for &w_task in &settings.w_tasks {
            for (i, method) in settings.methods.iter().enumerate() {
                let (cand, table) = select(settings, &idx, models, m, i, w_task)?;
                let runs = idx.runs(Phase::Test, i, &cand);
                let test = MetricSummary::of(&score_all(&runs, model)?, w_task);
                let selected = Hyperparameter::of(&cand.0);
                if let Some(h) = &selected {
                    selection.push(SelectionRow {
                        model: model.name.clone(),
                        w_task,
                        method: method.label.clone(),
                        candidates: table,
                        chosen: h.value,
                    });
                }
                rows.push(ResultRow {
                    model: model.name.clone(),
                    w_task,
                    method: method.label.clone(),
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
        let i = settings
            .methods
            .iter()
            .position(|m| m.label == c.method)
            .ok_or_else(|| {
                HilError::invalid_parameter("cross.method", &c.method, "no method has that label")
            })?;
        let w_task = settings.cross_w_task;
        let (cand, _) = select(settings, &idx, models, d, i, w_task)?;
        let runs = idx.runs(Phase::Test, i, &cand);
        let test = MetricSummary::of(&score_all(&runs, &models[sc])?, w_task);
        cross.push(CrossRow {
            method: c.method.clone(),
            decide: c.decide.clone(),
            score: c.score.clone(),
            w_task,
            selected: Hyperparameter::of(&cand.0),
            test,
        });
    }
    Ok(ProtocolResults {
        provenance: provenance.to_string(),
        n_env_seeds,
        spread,
        settings: settings.clone(),
        models: models.iter().map(|m| m.name.clone()).collect(),
        n_episodes: idx.records.len(),
        rows,
        cross,
        selection,
    })
}

/// One point of the trade-off frontier: a method at one grid value, its
/// test r_task against its test ΔWL under one model, whatever validation
/// would choose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrontierPoint {
    /// Scoring (and, for methods that read it, deciding) model.
    pub model: String,
    /// The method's label.
    pub method: String,
    /// The grid value, if the method is tuned.
    pub point: Option<Hyperparameter>,
    /// Test runs aggregated.
    pub n_runs: usize,
    /// Test r_task_avg.
    pub r_task_avg: Stat,
    /// Test ΔWL.
    pub delta_wl: Stat,
}

/// The frontier over every test run in `records`: every (model, method,
/// grid value of any grid variant).
pub fn frontier(
    settings: &ProtocolSettings,
    models: &[NamedModel],
    records: &[RunRecord],
) -> Result<Vec<FrontierPoint>> {
    let idx = Index {
        records: records.iter().collect(),
    };
    let mut out = Vec::new();
    for (m, model) in models.iter().enumerate() {
        for (i, method) in settings.methods.iter().enumerate() {
            for cand in candidates_at(&idx, settings.run_points(i)?, i, m) {
                let runs = idx.runs(Phase::Test, i, &cand);
                let scored = score_all(&runs, model)?;
                let col = |f: &dyn Fn(&EpisodeMetrics) -> f64| {
                    Stat::of(&scored.iter().map(f).collect::<Vec<_>>())
                };
                out.push(FrontierPoint {
                    model: model.name.clone(),
                    method: method.label.clone(),
                    point: Hyperparameter::of(&cand.0),
                    n_runs: scored.len(),
                    r_task_avg: col(&|s| s.r_task_avg),
                    delta_wl: col(&|s| s.delta_wl),
                });
            }
        }
    }
    Ok(out)
}

/// What `hil reproduce` reports: the paper's protocol (its seeds, its ±
/// std), the many-seed run beside it (± standard error), and the frontier.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Reproduction {
    /// The paper's protocol: `n_seeds` environment seeds.
    pub paper_protocol: ProtocolResults,
    /// The many-seed run (`many_seeds` environment seeds), if configured.
    pub many_seeds: Option<ProtocolResults>,
    /// Test r_task against ΔWL for every grid value, over every seed run.
    pub frontier: Vec<FrontierPoint>,
    /// The headline run (many-seed if any) selected again under each of the
    /// settings' grid variants, in order: what the claims' robustness
    /// across grids reads.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub grid_variants: Vec<ProtocolResults>,
}

impl Reproduction {
    /// Aggregates a run of [`crate::Protocol::run_all`].
    pub fn of(
        settings: &ProtocolSettings,
        models: &[NamedModel],
        records: &[RunRecord],
        provenance: &str,
    ) -> Result<Self> {
        let paper_protocol = aggregate(
            settings,
            models,
            records,
            provenance,
            settings.n_seeds,
            Spread::Std,
        )?;
        let many_seeds = if settings.many_seeds > settings.n_seeds {
            Some(aggregate(
                settings,
                models,
                records,
                provenance,
                settings.many_seeds,
                Spread::Se,
            )?)
        } else {
            None
        };
        let (n, spread) = if many_seeds.is_some() {
            (settings.many_seeds, Spread::Se)
        } else {
            (settings.n_seeds, Spread::Std)
        };
        let grid_variants = settings
            .variants()?
            .iter()
            .map(|v| aggregate(v, models, records, provenance, n, spread))
            .collect::<Result<_>>()?;
        Ok(Self {
            paper_protocol,
            many_seeds,
            frontier: frontier(settings, models, records)?,
            grid_variants,
        })
    }

    /// The headline results under every grid: the settings' own first, then
    /// each variant.
    pub fn by_grid(&self) -> impl Iterator<Item = &ProtocolResults> {
        std::iter::once(self.headline()).chain(&self.grid_variants)
    }

    /// The results with uncertainty: the many-seed run if there is one.
    pub fn headline(&self) -> &ProtocolResults {
        self.many_seeds.as_ref().unwrap_or(&self.paper_protocol)
    }
}
