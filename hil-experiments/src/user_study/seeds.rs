//! The user study over many seeds: each method's figures as mean ±
//! standard error over seeds, beside the paper's real-robot study.

use std::collections::BTreeMap;

use hil_stats::Stat;
use serde::Serialize;

use super::run::{MethodSummary, UserStudyResult};

/// The paper's real-robot user study, per method: (label, r_task_avg,
/// n_success per plate, n_q per plate), means (the paper's user-study
/// table).
pub const PAPER_STUDY: [(&str, f64, f64, f64); 3] = [
    ("LinUCB", 0.38, 2.00, 0.0),
    ("AlwaysQuery", 0.87, 2.68, 3.0),
    ("LinUCB-QG", 0.68, 2.53, 1.74),
];

/// One method over many seeds: each figure is the mean ± standard error
/// over seeds of each seed's mean per plate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodAcrossSeeds {
    /// The method's label.
    pub method: String,
    /// r_task_avg.
    #[serde(with = "hil_stats::summary::as_mean_sem")]
    pub r_task_avg: Stat,
    /// Items fed per plate.
    #[serde(with = "hil_stats::summary::as_mean_sem")]
    pub n_success_per_plate: Stat,
    /// Queries per plate.
    #[serde(with = "hil_stats::summary::as_mean_sem")]
    pub n_q_per_plate: Stat,
    /// Queries per plate at each food (a seed that never asked at a food
    /// counts 0 there).
    #[serde(with = "hil_stats::summary::as_mean_sem::map")]
    pub n_q_per_plate_by_food: BTreeMap<String, Stat>,
    /// Queries per plate at each attempt index (first attempt first).
    #[serde(with = "hil_stats::summary::as_mean_sem::seq")]
    pub n_q_per_plate_by_attempt: Vec<Stat>,
    /// The paper's real-study figures for a method of this label:
    /// r_task_avg, n_success and n_q per plate ([`PAPER_STUDY`]).
    pub paper: Option<[f64; 3]>,
}

/// Every method of `runs` (one result per seed, methods in the first
/// seed's order) over the seeds.
///
/// ```
/// use hil_experiments::user_study::across_seeds;
/// assert!(across_seeds(&[]).is_empty());
/// ```
pub fn across_seeds(runs: &[UserStudyResult]) -> Vec<MethodAcrossSeeds> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    first
        .methods
        .iter()
        .map(|m| of_method(runs, &m.method))
        .collect()
}

fn of_method(runs: &[UserStudyResult], label: &str) -> MethodAcrossSeeds {
    let mine: Vec<&MethodSummary> = runs
        .iter()
        .filter_map(|r| r.methods.iter().find(|m| m.method == label))
        .collect();
    let over = |f: &dyn Fn(&MethodSummary) -> f64| {
        Stat::of(&mine.iter().map(|m| f(m)).collect::<Vec<_>>())
    };
    let foods: std::collections::BTreeSet<&String> =
        mine.iter().flat_map(|m| m.n_q_by_food.keys()).collect();
    let depth = mine
        .iter()
        .map(|m| m.n_q_by_attempt.len())
        .max()
        .unwrap_or(0);
    MethodAcrossSeeds {
        method: label.to_string(),
        r_task_avg: over(&|m| m.r_task_avg),
        n_success_per_plate: over(&|m| m.n_success_per_plate),
        n_q_per_plate: over(&|m| m.n_q_per_plate),
        n_q_per_plate_by_food: foods
            .into_iter()
            .map(|f| {
                let at_food = over(&|m| m.n_q_by_food.get(f).copied().unwrap_or(0.0));
                (f.clone(), at_food)
            })
            .collect(),
        n_q_per_plate_by_attempt: (0..depth)
            .map(|i| over(&|m| m.n_q_by_attempt.get(i).copied().unwrap_or(0.0)))
            .collect(),
        paper: PAPER_STUDY
            .iter()
            .find(|p| p.0 == label)
            .map(|p| [p.1, p.2, p.3]),
    }
}
