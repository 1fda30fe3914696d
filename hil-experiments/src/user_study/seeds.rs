//! The user study over many seeds: the whole study (pretraining,
//! validation, plates) once per master seed, in parallel on the one job
//! runner, and each method's figures as mean ± standard error over seeds,
//! beside the paper's real-robot study.

use std::collections::BTreeMap;
use std::path::Path;

use hil_core::{HilError, Result};
use hil_jobs::Runner;
use hil_paper::methods::PaperMethod;
use hil_stats::Stat;
use serde::Serialize;

use super::config::UserStudyConfig;
use super::reference::PublishedReference;
use super::run::{MethodSummary, Protocol, Selection, UserStudyResult};
use crate::claims::Verdict;

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
    /// r_task_avg, n_success and n_q per plate ([`hil_paper::user_study::OBJECTIVE`]).
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
        paper: PaperMethod::from_label(label)
            .and_then(hil_paper::user_study::row)
            .map(|p| [p.r_task_avg.mean, p.n_success.mean, p.n_q_mean()]),
    }
}

/// The study run once per master seed, aggregated over the seeds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UserStudyOverSeeds {
    /// The master seeds, in order.
    pub seeds: Vec<u64>,
    /// Every method over the seeds ([`across_seeds`]).
    pub methods: Vec<MethodAcrossSeeds>,
    /// Every seed's selections of tuned hyperparameters, in seed order.
    pub selections: Vec<Vec<Selection>>,
    /// Each pair of methods' r_task_avg, paired over seeds
    /// ([`paired_differences`]).
    pub differences: Vec<PairedDifference>,
    /// The first seed's protocol.
    pub protocol: Protocol,
    /// What an always-asking robot scores in expectation at the published
    /// rates of the actions the expert names, when the environment is
    /// calibrated to a published table ([`PublishedReference`]): the bound
    /// a simulated AlwaysQuery is read against.
    pub published_reference: Option<PublishedReference>,
}

/// One method's r_task_avg against another's, paired over seeds: every
/// seed runs every method on the same foods and channel seeds, so the
/// per-seed difference removes what the seeds share and its standard error
/// is the one a "beats by more than 2 SE" reading needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairedDifference {
    /// The method whose r_task_avg comes first in the difference.
    pub method: String,
    /// The method subtracted.
    pub baseline: String,
    /// `method − baseline` on each seed, as mean ± standard error over
    /// the seeds that ran both.
    #[serde(with = "hil_stats::summary::as_mean_sem")]
    pub r_task_avg: Stat,
    /// The paper's real-study difference, where it reports both methods.
    pub paper: Option<f64>,
    /// Against the paper's sign: `holds` (its sign by more than 2 SE),
    /// `not resolved` or `opposite` ([`Verdict`]); `None` without paper
    /// figures or with fewer than two seeds.
    pub verdict: Option<&'static str>,
}

/// Every pair of methods of `runs` (in the first seed's order), each
/// oriented so that the paper's higher method comes first (later minus
/// earlier where the paper has no figures), with its r_task_avg
/// difference paired over seeds.
///
/// ```
/// use hil_experiments::user_study::{UserStudyConfig, paired_differences};
/// let cfg = UserStudyConfig::parse(
///     "repetitions = 1\n[environment]\ntype = \"food_replay\"\nfoods = [\"banana\"]\nitems_per_episode = 2\n[[methods]]\nlabel = \"LinUCB\"\npolicy = { type = \"linucb\", alpha = 0.5 }\n[[methods]]\nlabel = \"AlwaysQuery\"\npolicy = { type = \"always_query\", alpha = 0.5 }\n",
///     "study.toml".as_ref(),
/// )
/// .unwrap();
/// let runs: Vec<_> = [3, 4]
///     .iter()
///     .map(|&s| cfg.run_on_seed(".".as_ref(), s, |_| {}).unwrap())
///     .collect();
/// let d = paired_differences(&runs);
/// // The paper's AlwaysQuery fed more than its LinUCB: it comes first.
/// assert_eq!((d[0].method.as_str(), d[0].baseline.as_str()), ("AlwaysQuery", "LinUCB"));
/// assert_eq!(d[0].r_task_avg.n, 2);
/// ```
pub fn paired_differences(runs: &[UserStudyResult]) -> Vec<PairedDifference> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    let labels: Vec<&str> = first.methods.iter().map(|m| m.method.as_str()).collect();
    let paper = |label: &str| {
        PaperMethod::from_label(label)
            .and_then(hil_paper::user_study::row)
            .map(|p| p.r_task_avg.mean)
    };
    let mut out = Vec::new();
    for (i, &earlier) in labels.iter().enumerate() {
        for &later in &labels[i + 1..] {
            let (a, b) = match (paper(earlier), paper(later)) {
                (Some(pe), Some(pl)) if pe > pl => (earlier, later),
                _ => (later, earlier),
            };
            out.push(paired(
                runs,
                a,
                b,
                paper(a).zip(paper(b)).map(|(pa, pb)| pa - pb),
            ));
        }
    }
    out
}

fn paired(runs: &[UserStudyResult], a: &str, b: &str, paper: Option<f64>) -> PairedDifference {
    let r_task = |run: &UserStudyResult, label: &str| {
        run.methods
            .iter()
            .find(|m| m.method == label)
            .map(|m| m.r_task_avg)
    };
    let per_seed: Vec<f64> = runs
        .iter()
        .filter_map(|run| Some(r_task(run, a)? - r_task(run, b)?))
        .collect();
    let r_task_avg = Stat::of(&per_seed);
    let verdict = paper
        .zip(r_task_avg.sem())
        .map(|(p, se)| Verdict::of_difference(r_task_avg.mean, se, p > 0.0).word());
    PairedDifference {
        method: a.to_string(),
        baseline: b.to_string(),
        r_task_avg,
        paper,
        verdict,
    }
}

/// The value a tuned method's validation chose on each seed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChosenAcrossSeeds {
    /// The method's label.
    pub method: String,
    /// The tuned hyperparameter.
    pub parameter: String,
    /// The value chosen on each seed, in seed order.
    pub values: Vec<f64>,
    /// Their mean ± standard error.
    #[serde(with = "hil_stats::summary::as_mean_sem")]
    pub mean: Stat,
}

impl UserStudyOverSeeds {
    /// Aggregates one result per seed (in the order of `seeds`).
    pub fn of(seeds: Vec<u64>, runs: &[UserStudyResult]) -> Result<Self> {
        let first = runs
            .first()
            .ok_or_else(|| HilError::invalid_parameter("seeds", "[]", "needs at least one seed"))?;
        Ok(Self {
            seeds,
            methods: across_seeds(runs),
            differences: paired_differences(runs),
            selections: runs.iter().map(|r| r.selections.clone()).collect(),
            protocol: first.protocol.clone(),
            published_reference: None,
        })
    }

    /// Per tuned method (in order of first appearance), the values its
    /// validation chose over the seeds.
    pub fn chosen(&self) -> Vec<ChosenAcrossSeeds> {
        let mut out: Vec<ChosenAcrossSeeds> = Vec::new();
        for sel in self.selections.iter().flatten() {
            match out.iter_mut().find(|c| c.method == sel.method) {
                Some(c) => c.values.push(sel.chosen),
                None => out.push(ChosenAcrossSeeds {
                    method: sel.method.clone(),
                    parameter: sel.parameter.clone(),
                    values: vec![sel.chosen],
                    mean: Stat::of(&[]),
                }),
            }
        }
        for c in &mut out {
            c.mean = Stat::of(&c.values);
        }
        out
    }
}

impl UserStudyConfig {
    /// Runs the whole study once per master seed in `seeds`, in parallel on
    /// `runner` (each seed's result is the one [`UserStudyConfig::run`] gives
    /// with that seed, whatever the thread count), calling `on_seed` as each
    /// seed finishes; the first failing seed's error is returned.
    ///
    /// ```
    /// use hil_experiments::user_study::UserStudyConfig;
    /// let cfg = UserStudyConfig::parse(
    ///     "repetitions = 1\n[environment]\ntype = \"food_replay\"\nfoods = [\"banana\"]\nitems_per_episode = 2\n[[methods]]\nlabel = \"AQ\"\npolicy = { type = \"always_query\", alpha = 0.5 }\n",
    ///     "study.toml".as_ref(),
    /// )
    /// .unwrap();
    /// let runner = hil_jobs::Runner::new(2).unwrap();
    /// let over = cfg.run_over_seeds(".".as_ref(), &[3, 4], &runner, &|_| {}).unwrap();
    /// assert_eq!(over.seeds, [3, 4]);
    /// assert_eq!(over.methods[0].n_q_per_plate.mean, 2.0); // asks at every item
    /// ```
    pub fn run_over_seeds(
        &self,
        base_dir: &Path,
        seeds: &[u64],
        runner: &Runner,
        on_seed: &(dyn Fn(u64) + Sync),
    ) -> Result<UserStudyOverSeeds> {
        let runs = runner.map(seeds, |&seed| {
            let run = self.run_on_seed(base_dir, seed, |_| {});
            on_seed(seed);
            run
        })?;
        let mut over = UserStudyOverSeeds::of(seeds.to_vec(), &runs)?;
        over.published_reference =
            PublishedReference::of(self.environment.as_ref(), self.session.n_att)?;
        Ok(over)
    }
}
