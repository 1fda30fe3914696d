//! The paper's episode metrics, defined once for every environment.

use serde::{Deserialize, Serialize};

use crate::error::{HilError, Result};
use crate::event::{StepDecision, StepEvent};
use crate::time::Timestep;
use crate::workload::{QueryHistory, WorkloadModel, check_wl0, workload_at};

/// Metrics of one episode, with the paper's definitions.
///
/// T is the episode's last timestep, I the number of items, Q_T the queries
/// asked and f the *scoring* workload model:
/// - `r_task_avg` = (1/T) Σ_t r_task(x_t, a_t), where r_task is the executed
///   action's success probability when the environment knows it, else the
///   0/1 outcome;
/// - `wl_final` = WL_T = f(WL_0, Q_T) evaluated at T
///   ([`crate::workload::workload_at`]), so a policy that never asks gets
///   f(WL_0, ∅) and a model whose workload decays once queries leave its
///   history window is scored after the decay; `delta_wl` = ΔWL = WL_T − WL_0;
/// - `t_conv` = mean number of timesteps spent per item (attempts until
///   success, or N_att for an item never acquired);
/// - `f_q` = fraction of items at which at least one query was asked;
/// - `f_fail_food` = fraction of items never acquired;
/// - `f_auto_food` = fraction of items acquired without any query;
/// - `n_success` = number of items acquired; `n_q` = number of query steps.
///
/// `M_wt(w_task)` = w_task·r_task_avg − (1 − w_task)·ΔWL is [`EpisodeMetrics::m_wt`].
/// Scoring the same episode with another model (the paper's cross-data
/// experiment: decide with one model, score with another) is
/// [`EpisodeMetrics::rescored`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct EpisodeMetrics {
    /// Mean task reward per timestep.
    pub r_task_avg: f64,
    /// Initial workload WL_0.
    pub wl0: f64,
    /// WL_T = f(WL_0, Q_T) at the last timestep, under `scoring_model`.
    pub wl_final: f64,
    /// ΔWL = WL_T − WL_0.
    pub delta_wl: f64,
    /// Mean timesteps per item.
    pub t_conv: f64,
    /// Fraction of items with a query.
    pub f_q: f64,
    /// Fraction of items never acquired.
    pub f_fail_food: f64,
    /// Fraction of items acquired without a query.
    pub f_auto_food: f64,
    /// Items acquired.
    pub n_success: usize,
    /// Query steps.
    pub n_q: usize,
    /// Items presented.
    pub n_items: usize,
    /// Timesteps T.
    pub n_steps: usize,
    /// The last timestep T (0 for an empty episode).
    pub t_final: Timestep,
    /// The queries asked, Q_T (what rescoring under another model needs).
    pub queries: QueryHistory,
    /// Name of the workload model WL_T was computed with.
    pub scoring_model: String,
}

impl EpisodeMetrics {
    /// Computes the metrics of an episode from its events, in order, scoring
    /// workload with `model` from `wl0`.
    ///
    /// ```
    /// use hil_core::EpisodeMetrics;
    /// use hil_conformance::fixtures::CountingWorkload;
    /// let m = EpisodeMetrics::from_events(&[], 0.5, &CountingWorkload::new(0.1)).unwrap();
    /// assert_eq!(m.n_steps, 0);
    /// assert_eq!(m.delta_wl, 0.0);
    /// assert!((m.m_wt(0.7) - 0.0).abs() < 1e-12);
    /// ```
    pub fn from_events(events: &[StepEvent], wl0: f64, model: &dyn WorkloadModel) -> Result<Self> {
        check_wl0(wl0)?;
        let mut items: Vec<ItemTally> = Vec::new();
        let mut r_sum = 0.0;
        let mut queries = QueryHistory::new();
        for e in events {
            let s = &e.step;
            let new_item = items.last().is_none_or(|it| it.index != s.item_index);
            if new_item {
                if items.iter().any(|it| it.index == s.item_index) {
                    return Err(HilError::invalid_input(
                        format!("event at t = {}", s.t),
                        format!("item {} reappears after another item", s.item_index),
                    ));
                }
                items.push(ItemTally {
                    index: s.item_index,
                    ..ItemTally::default()
                });
            }
            let it = items.last_mut().expect("pushed above");
            it.steps += 1;
            it.success |= e.outcome.success;
            if let StepDecision::Query { kind, .. } = s.decision {
                it.queried = true;
                queries.push(s.t, kind)?;
            }
            r_sum += e.task_reward();
        }
        let n_items = items.len();
        let frac = |pred: &dyn Fn(&ItemTally) -> bool| {
            if n_items == 0 {
                0.0
            } else {
                items.iter().filter(|it| pred(it)).count() as f64 / n_items as f64
            }
        };
        let n_steps = events.len();
        let t_final = events.last().map_or(0, |e| e.step.t);
        let wl_final = workload_at(model, wl0, &queries, t_final)?;
        Ok(Self {
            r_task_avg: if n_steps == 0 {
                0.0
            } else {
                r_sum / n_steps as f64
            },
            wl0,
            wl_final,
            delta_wl: wl_final - wl0,
            t_conv: if n_items == 0 {
                0.0
            } else {
                n_steps as f64 / n_items as f64
            },
            f_q: frac(&|it| it.queried),
            f_fail_food: frac(&|it| !it.success),
            f_auto_food: frac(&|it| it.success && !it.queried),
            n_success: items.iter().filter(|it| it.success).count(),
            n_q: queries.len(),
            n_items,
            n_steps,
            t_final,
            queries,
            scoring_model: model.name().to_string(),
        })
    }

    /// The same episode scored with another workload model: WL_T, ΔWL (and
    /// so M_wt) follow `model`; every other figure is unchanged.
    ///
    /// ```
    /// use hil_core::EpisodeMetrics;
    /// use hil_conformance::fixtures::CountingWorkload;
    /// let m = EpisodeMetrics::from_events(&[], 0.5, &CountingWorkload::new(0.1)).unwrap();
    /// let r = m.rescored(&CountingWorkload::new(0.3)).unwrap();
    /// assert_eq!((r.r_task_avg, r.delta_wl), (m.r_task_avg, 0.0));
    /// ```
    pub fn rescored(&self, model: &dyn WorkloadModel) -> Result<Self> {
        let wl_final = workload_at(model, self.wl0, &self.queries, self.t_final)?;
        Ok(Self {
            wl_final,
            delta_wl: wl_final - self.wl0,
            scoring_model: model.name().to_string(),
            ..self.clone()
        })
    }

    /// The surrogate objective M_wt = w_task·r_task_avg − (1 − w_task)·ΔWL.
    pub fn m_wt(&self, w_task: f64) -> f64 {
        w_task * self.r_task_avg - (1.0 - w_task) * self.delta_wl
    }
}

#[derive(Debug, Default)]
struct ItemTally {
    index: usize,
    steps: usize,
    success: bool,
    queried: bool,
}
