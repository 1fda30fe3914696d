//! Cross-validated model selection: the paper's appendix table.
//!
//! Every candidate (Constant, Average, Granger × H × 4 variants,
//! Exp-Impulse) is scored by K-fold cross-validation (K = 4) on each dataset;
//! ridge penalties are tuned by an inner J-fold cross-validation (J = 5) over
//! a log grid inside each outer training set. The candidate with the lowest
//! median test MSE wins.
//!
//! Speed: each pair is encoded once as a sparse row for the longest history;
//! the normal equations of each of the K·J parts are accumulated once, and
//! every training set's equations are sums (or differences) of them. Designs
//! for shorter histories are prefixes. Folds run on all cores.

use hil_jobs::Runner;
use std::fmt::Write as _;

use hil_config::limits;
use hil_core::{HilError, QueryHistory, Result};
use hil_stats::{mean, mean_std, median};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use crate::datasets::{Dataset, DatasetId, TrainingPair, by_shared_history};
use crate::features::{SparseRow, n_columns};
use crate::fit::{BoxLsq, Gram};
use crate::models::{
    AverageModel, ConstantModel, ExpImpulseModel, GrangerModel, GrangerVariant, ModelSpec,
};
use hil_core::WorkloadInput;

/// Options of a selection run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectOptions {
    /// History lengths H to try.
    pub histories: Vec<usize>,
    /// Ridge penalties to try (the paper: a log grid from 1e-3 to 1e2).
    pub lambdas: Vec<f64>,
    /// Outer folds (4).
    pub outer_folds: usize,
    /// Inner folds for the ridge penalty (5).
    pub inner_folds: usize,
    /// Seed of the fold assignment.
    pub seed: u64,
    /// Worker threads ([`hil_jobs::Runner::new`]: 0 = one per core, or `RAYON_NUM_THREADS`).
    pub threads: usize,
}

impl Default for SelectOptions {
    fn default() -> Self {
        Self {
            histories: vec![1, 5, 10, 15, 20, 25, 30],
            lambdas: (0..=5).map(|e| 10f64.powi(e - 3)).collect(),
            outer_folds: 4,
            inner_folds: 5,
            seed: 0,
            threads: 0,
        }
    }
}

impl SelectOptions {
    fn validate(&self) -> Result<()> {
        if self.outer_folds < 2 || self.inner_folds < 2 {
            return Err(HilError::invalid_parameter(
                "folds",
                format!("{}/{}", self.outer_folds, self.inner_folds),
                "need at least 2 outer and 2 inner folds",
            ));
        }
        if self.histories.is_empty() {
            return Err(HilError::invalid_parameter(
                "histories",
                "[]",
                "need at least one H ≥ 1",
            ));
        }
        for (i, &h) in self.histories.iter().enumerate() {
            limits::check_count(&format!("histories[{i}]"), h, limits::HISTORY)?;
        }
        if self.lambdas.is_empty() || self.lambdas.iter().any(|l| !(l.is_finite() && *l >= 0.0)) {
            return Err(HilError::invalid_parameter(
                "lambdas",
                format!("{:?}", self.lambdas),
                "need at least one finite λ ≥ 0",
            ));
        }
        Ok(())
    }
}

/// One model in the comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case")]
pub enum Candidate {
    /// WL_t = WL_0.
    Constant,
    /// Mean WL_0 of the training set.
    Average,
    /// A Granger variant with history `h`.
    Granger {
        /// Variant.
        variant: GrangerVariant,
        /// History length.
        h: usize,
    },
    /// Exp-Impulse.
    ExpImpulse,
}

impl Candidate {
    /// Table label (`Constant`, `Granger-R`, ...).
    pub fn label(&self) -> &'static str {
        match self {
            Self::Constant => "Constant",
            Self::Average => "Average",
            Self::Granger { variant, .. } => variant.label(),
            Self::ExpImpulse => "Exp-Impulse",
        }
    }

    /// The model name [`Candidate::parse`] reads (`granger_n`, ...): with
    /// [`Candidate::history`], `parse(key, history)` gives the candidate back.
    pub fn key(&self) -> &'static str {
        match self {
            Self::Constant => "constant",
            Self::Average => "average",
            Self::ExpImpulse => "exp_impulse",
            Self::Granger { variant, .. } => match variant {
                GrangerVariant::Plain => "granger",
                GrangerVariant::Nonnegative => "granger_n",
                GrangerVariant::Ridge => "granger_r",
                GrangerVariant::RidgeNonnegative => "granger_rn",
                GrangerVariant::Simulation => "granger_sim",
            },
        }
    }

    /// History length, if any.
    pub fn history(&self) -> Option<usize> {
        match self {
            Self::Granger { h, .. } => Some(*h),
            _ => None,
        }
    }

    /// Checks a Granger history against `1..=`[`limits::HISTORY`], before
    /// a design of 9·H + 2 columns is allocated; every fit and
    /// cross-validation runs it, whichever way the candidate was made
    /// ([`Candidate::parse`], or deserialised from a selection row).
    pub fn validate(&self) -> Result<()> {
        match self.history() {
            Some(h) => limits::check_count("history", h, limits::HISTORY),
            None => Ok(()),
        }
    }

    /// Parses a CLI model name: `constant`, `average`, `exp_impulse`,
    /// `granger`, `granger_n`, `granger_r`, `granger_rn`, `granger_sim`
    /// (Granger needs `h`; `granger_sim` defaults to H = 10).
    pub fn parse(name: &str, h: Option<usize>) -> Result<Self> {
        let granger = |variant, default: Option<usize>| match h.or(default) {
            Some(h) => {
                let cand = Self::Granger { variant, h };
                cand.validate()?;
                Ok(cand)
            }
            None => Err(HilError::invalid_parameter(
                "history",
                "(missing)",
                "Granger models need --history H ≥ 1",
            )),
        };
        // A history given to a model without one is a mistake, not ignored.
        let historyless = |cand: Self| match h {
            None => Ok(cand),
            Some(h) => Err(HilError::invalid_parameter(
                "history",
                h,
                format!("only Granger models have a history, not `{name}`"),
            )),
        };
        match name {
            "constant" => historyless(Self::Constant),
            "average" => historyless(Self::Average),
            "exp_impulse" => historyless(Self::ExpImpulse),
            "granger" => granger(GrangerVariant::Plain, None),
            "granger_n" => granger(GrangerVariant::Nonnegative, None),
            "granger_r" => granger(GrangerVariant::Ridge, None),
            "granger_rn" => granger(GrangerVariant::RidgeNonnegative, None),
            "granger_sim" => granger(GrangerVariant::Simulation, Some(10)),
            _ => Err(HilError::invalid_parameter(
                "model",
                name,
                "expected constant, average, exp_impulse, granger, granger_n, granger_r, granger_rn or granger_sim",
            )),
        }
    }

    /// All candidates of the paper's table for `histories`.
    pub fn table(histories: &[usize]) -> Vec<Self> {
        let mut v = vec![Self::Constant, Self::Average];
        for variant in GrangerVariant::TABLE {
            for &h in histories {
                v.push(Self::Granger { variant, h });
            }
        }
        v.push(Self::ExpImpulse);
        v
    }
}

/// Cross-validation scores of one candidate on one dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScoreRow {
    /// Dataset.
    pub dataset: DatasetId,
    /// The candidate.
    pub candidate: Candidate,
    /// Test MSE per outer fold.
    pub fold_mse: Vec<f64>,
    /// Ridge penalty chosen per fold (ridge variants).
    pub fold_lambda: Vec<Option<f64>>,
    /// Mean test MSE.
    pub mean: f64,
    /// Population standard deviation of the test MSE.
    pub std: f64,
    /// Median test MSE.
    pub median: f64,
}

/// The full selection result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SelectionTable {
    /// Options used.
    pub options: SelectOptions,
    /// Pairs per dataset.
    pub n_pairs: Vec<(DatasetId, usize)>,
    /// One row per (dataset, candidate).
    pub rows: Vec<ScoreRow>,
}

/// A training split (parts and inner CV groups) with its normal equations.
#[derive(Debug)]
pub struct Split {
    train: Vec<usize>,
    inner: Vec<Vec<usize>>,
    g_train: Gram,
    g_inner: Vec<Gram>,
}

/// The pairs of a dataset encoded once, split into parts, with the normal
/// equations of each part.
#[derive(Debug)]
pub struct Problem<'a> {
    pairs: Vec<&'a TrainingPair>,
    rows: Vec<SparseRow>,
    part_rows: Vec<Vec<usize>>,
    part_grams: Vec<Gram>,
}

impl<'a> Problem<'a> {
    /// Encodes `pairs` for histories up to `h_max` and deals them into
    /// `n_parts` parts after a seeded shuffle.
    pub fn new(pairs: &'a [TrainingPair], h_max: usize, n_parts: usize, seed: u64) -> Self {
        let mut order: Vec<usize> = (0..pairs.len()).collect();
        order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
        let k = n_columns(h_max);
        let rows: Vec<SparseRow> = pairs.iter().map(|p| SparseRow::of_pair(p, h_max)).collect();
        let mut part_rows = vec![Vec::new(); n_parts];
        let mut part_grams = vec![Gram::new(k); n_parts];
        for (pos, &i) in order.iter().enumerate() {
            let part = pos % n_parts;
            part_rows[part].push(i);
            part_grams[part].add_row(&rows[i]);
        }
        Self {
            pairs: pairs.iter().collect(),
            rows,
            part_rows,
            part_grams,
        }
    }

    fn gram_of(&self, parts: &[usize]) -> Gram {
        let mut g = Gram::new(self.part_grams[0].k);
        for &p in parts {
            g.accumulate(&self.part_grams[p], 1.0);
        }
        g
    }

    fn rows_of<'s>(&'s self, parts: &'s [usize]) -> impl Iterator<Item = usize> + 's {
        parts
            .iter()
            .flat_map(move |&p| self.part_rows[p].iter().copied())
    }

    fn mse_linear(&self, parts: &[usize], w: &[f64]) -> f64 {
        let (mut s, mut n) = (0.0, 0usize);
        for i in self.rows_of(parts) {
            let r = &self.rows[i];
            let e = r.dot_prefix(w).clamp(0.0, 1.0) - r.y;
            s += e * e;
            n += 1;
        }
        s / n.max(1) as f64
    }

    /// Test MSE of a model that is not linear in the design rows, in
    /// O(pairs + queries): Exp-Impulse through its carried-forward sums,
    /// others pair by pair on each condition's history grown in step (a
    /// fresh copy of every prefix would cost O(pairs × queries)).
    fn mse_model(&self, parts: &[usize], spec: &ModelSpec) -> Result<f64> {
        let pairs: Vec<&TrainingPair> = self.rows_of(parts).map(|i| self.pairs[i]).collect();
        let predictions = match spec {
            ModelSpec::ExpImpulse(m) => m.predict_pairs(&pairs),
            other => {
                let mut out = vec![0.0; pairs.len()];
                for group in by_shared_history(&pairs) {
                    let whole = pairs[group[0]].history.whole().records();
                    let mut history = QueryHistory::new();
                    for i in group {
                        let p = pairs[i];
                        for r in &whole[history.len()..p.history.len()] {
                            history.push(r.t, r.kind)?;
                        }
                        out[i] = other
                            .as_model()
                            .predict(&WorkloadInput::new(p.wl0, &history, p.t))?;
                    }
                }
                out
            }
        };
        let s: f64 = pairs
            .iter()
            .zip(&predictions)
            .map(|(p, y)| (y - p.target).powi(2))
            .sum();
        Ok(s / pairs.len().max(1) as f64)
    }

    fn solve(
        variant: GrangerVariant,
        gram: &Gram,
        h: usize,
        lambda: f64,
        start: Option<&[f64]>,
    ) -> Result<Vec<f64>> {
        let k = n_columns(h);
        let g = gram.prefix(k);
        let (lower, upper) = variant.bounds(h);
        let mut p = BoxLsq::plain(&g);
        p.lower = lower;
        p.upper = upper;
        if variant.is_ridge() {
            p.ridge = (0..k).map(|i| if i == 1 { 0.0 } else { lambda }).collect();
        }
        p.solve(start)
    }

    /// The normal equations of a training split and of its inner CV
    /// training sets (computed once, shared by every candidate).
    pub fn split(&self, train: &[usize], inner: &[Vec<usize>]) -> Split {
        let g_train = self.gram_of(train);
        let g_inner = inner
            .iter()
            .map(|grp| {
                let mut g = g_train.clone();
                g.accumulate(&self.gram_of(grp), -1.0);
                g
            })
            .collect();
        Split {
            train: train.to_vec(),
            inner: inner.to_vec(),
            g_train,
            g_inner,
        }
    }

    /// Fits a Granger variant on `split`; ridge variants pick λ from
    /// `lambdas` by cross-validation over the split's inner groups.
    /// Returns the coefficients and the λ used.
    pub fn fit_granger(
        &self,
        variant: GrangerVariant,
        h: usize,
        split: &Split,
        lambdas: &[f64],
    ) -> Result<(Vec<f64>, Option<f64>)> {
        if !variant.is_ridge() {
            return Ok((Self::solve(variant, &split.g_train, h, 0.0, None)?, None));
        }
        let mut best = (f64::INFINITY, lambdas[0]);
        let mut warm: Vec<Option<Vec<f64>>> = vec![None; split.inner.len()];
        for &lambda in lambdas {
            let mut inner_mse = Vec::with_capacity(split.inner.len());
            for (j, grp) in split.inner.iter().enumerate() {
                let w = Self::solve(variant, &split.g_inner[j], h, lambda, warm[j].as_deref())?;
                inner_mse.push(self.mse_linear(grp, &w));
                warm[j] = Some(w);
            }
            let score = mean(&inner_mse);
            if score < best.0 {
                best = (score, lambda);
            }
        }
        Ok((
            Self::solve(variant, &split.g_train, h, best.1, None)?,
            Some(best.1),
        ))
    }

    /// Fits `cand` on `split` (inner groups tune ridge penalties).
    pub fn fit(
        &self,
        cand: Candidate,
        split: &Split,
        lambdas: &[f64],
    ) -> Result<(ModelSpec, Option<f64>)> {
        let pairs: Vec<&TrainingPair> = self.rows_of(&split.train).map(|i| self.pairs[i]).collect();
        Ok(match cand {
            Candidate::Constant => (ModelSpec::Constant(ConstantModel {}), None),
            Candidate::Average => (ModelSpec::Average(AverageModel::fit(&pairs)?), None),
            Candidate::ExpImpulse => (ModelSpec::ExpImpulse(ExpImpulseModel::fit(&pairs)?), None),
            Candidate::Granger { variant, h } => {
                let (w, lambda) = self.fit_granger(variant, h, split, lambdas)?;
                (
                    ModelSpec::Granger(GrangerModel::from_coefficients(variant, h, &w, lambda)?),
                    lambda,
                )
            }
        })
    }

    /// Test MSE of `spec` on `parts` (clamped predictions).
    pub fn test_mse(&self, parts: &[usize], spec: &ModelSpec) -> Result<f64> {
        match spec {
            ModelSpec::Granger(m) => Ok(self.mse_linear(parts, &m.coefficients())),
            other => self.mse_model(parts, other),
        }
    }
}

/// Per-fold (test MSE, chosen λ) of one candidate.
type FoldScores = Vec<(f64, Option<f64>)>;

/// Outer fold `o` of a K×J part layout: (train parts, inner groups, test parts).
fn fold_layout(o: usize, k: usize, j: usize) -> (Vec<usize>, Vec<Vec<usize>>, Vec<usize>) {
    let part = |outer: usize, inner: usize| outer * j + inner;
    let train: Vec<usize> = (0..k)
        .filter(|&x| x != o)
        .flat_map(|x| (0..j).map(move |i| part(x, i)))
        .collect();
    let inner: Vec<Vec<usize>> = (0..j)
        .map(|i| (0..k).filter(|&x| x != o).map(|x| part(x, i)).collect())
        .collect();
    let test: Vec<usize> = (0..j).map(|i| part(o, i)).collect();
    (train, inner, test)
}

/// Part layout of a K·J problem: pair at shuffled position `pos` goes to part
/// `pos % (K·J)`, so part `o·J + i` belongs to outer fold `o`.
fn n_parts(opts: &SelectOptions) -> usize {
    opts.outer_folds * opts.inner_folds
}

fn score_row(dataset: DatasetId, candidate: Candidate, fold: Vec<(f64, Option<f64>)>) -> ScoreRow {
    let fold_mse: Vec<f64> = fold.iter().map(|f| f.0).collect();
    let (mean, std) = mean_std(&fold_mse);
    ScoreRow {
        dataset,
        candidate,
        median: median(&fold_mse),
        mean,
        std,
        fold_lambda: fold.iter().map(|f| f.1).collect(),
        fold_mse,
    }
}

/// Cross-validates `candidates` on `datasets`.
///
/// ```
/// use hil_workload::{datasets::{Dataset, DatasetId}, select::*, synth::SynthConfig};
/// let study = SynthConfig::small(8, 4).generate(1).unwrap();
/// let d = Dataset::build(&study, DatasetId::D12).unwrap();
/// let opts = SelectOptions { histories: vec![1, 5], ..SelectOptions::default() };
/// let table = cross_validate(&[&d], &Candidate::table(&opts.histories), &opts).unwrap();
/// let best = table.best(DatasetId::D12).unwrap();
/// assert!(best.median < table.row(DatasetId::D12, Candidate::Constant).unwrap().median);
/// ```
pub fn cross_validate(
    datasets: &[&Dataset],
    candidates: &[Candidate],
    opts: &SelectOptions,
) -> Result<SelectionTable> {
    opts.validate()?;
    for c in candidates {
        c.validate()?;
    }
    let h_max = candidates
        .iter()
        .filter_map(Candidate::history)
        .max()
        .unwrap_or(1);
    let problems: Vec<Problem<'_>> = datasets
        .iter()
        .map(|d| Problem::new(&d.pairs, h_max, n_parts(opts), opts.seed))
        .collect();
    for (d, p) in datasets.iter().zip(&problems) {
        if p.part_rows.iter().any(Vec::is_empty) {
            return Err(HilError::invalid_input(
                format!("dataset {}", d.id.as_str()),
                format!(
                    "{} pairs are too few for {}×{} folds",
                    d.pairs.len(),
                    opts.outer_folds,
                    opts.inner_folds
                ),
            ));
        }
    }
    // one task per (dataset, outer fold)
    let tasks: Vec<(usize, usize)> = (0..datasets.len())
        .flat_map(|d| (0..opts.outer_folds).map(move |o| (d, o)))
        .collect();
    // Results come back in task order, whatever the thread count.
    let flat: Vec<(usize, usize, FoldScores)> = Runner::new(opts.threads)?.map(
        &tasks,
        |&(d, o)| -> Result<(usize, usize, FoldScores)> {
            let (train, inner, test) = fold_layout(o, opts.outer_folds, opts.inner_folds);
            let p = &problems[d];
            let split = p.split(&train, &inner);
            let mut scores = Vec::with_capacity(candidates.len());
            for &c in candidates {
                let (spec, lambda) = p.fit(c, &split, &opts.lambdas)?;
                scores.push((p.test_mse(&test, &spec)?, lambda));
            }
            Ok((d, o, scores))
        },
    )?;
    let mut per: Vec<Vec<FoldScores>> = vec![vec![Vec::new(); candidates.len()]; datasets.len()];
    for (d, _, scores) in flat {
        for (c, s) in scores.into_iter().enumerate() {
            per[d][c].push(s);
        }
    }
    let mut rows = Vec::new();
    for (d, ds) in datasets.iter().enumerate() {
        for (c, &cand) in candidates.iter().enumerate() {
            rows.push(score_row(ds.id, cand, std::mem::take(&mut per[d][c])));
        }
    }
    Ok(SelectionTable {
        options: opts.clone(),
        n_pairs: datasets.iter().map(|d| (d.id, d.pairs.len())).collect(),
        rows,
    })
}

/// Fits `cand` on the whole dataset; ridge penalties by inner CV on it.
pub fn fit_on_all(
    dataset: &Dataset,
    cand: Candidate,
    opts: &SelectOptions,
) -> Result<(ModelSpec, Option<f64>)> {
    opts.validate()?;
    cand.validate()?;
    let p = Problem::new(
        &dataset.pairs,
        cand.history().unwrap_or(1),
        opts.inner_folds,
        opts.seed,
    );
    let train: Vec<usize> = (0..opts.inner_folds).collect();
    let inner: Vec<Vec<usize>> = (0..opts.inner_folds).map(|i| vec![i]).collect();
    p.fit(cand, &p.split(&train, &inner), &opts.lambdas)
}

/// Fits `cand` on population `id` of `study` ([`fit_on_all`]) as a named
/// model file whose provenance records the study, the population, the
/// number of pairs and any ridge penalty chosen. `name` defaults to
/// `{key}_{population}[_h{H}]` (e.g. `granger_n_d12_h5`).
pub fn fit_study_model(
    study: &crate::study::Study,
    id: DatasetId,
    cand: Candidate,
    opts: &SelectOptions,
    name: Option<String>,
) -> Result<crate::models::FittedModel> {
    let d = Dataset::build(study, id)?;
    let (spec, lambda) = fit_on_all(&d, cand, opts)?;
    let name = name.unwrap_or_else(|| {
        format!(
            "{}_{}{}",
            cand.key(),
            id.as_str(),
            cand.history().map_or(String::new(), |h| format!("_h{h}"))
        )
    });
    Ok(crate::models::FittedModel::new(
        name,
        spec,
        crate::models::Provenance {
            dataset: Some(id.as_str().into()),
            data: Some(study.source().display().to_string()),
            n_pairs: Some(d.pairs.len()),
            cv_test_mse: None,
            note: lambda.map(|l| format!("ridge λ = {l} chosen by 5-fold CV")),
        },
    ))
}

/// Cross-validated model selection on a study: every candidate of the
/// paper's table (with `opts.histories`) scored by nested CV on each of its
/// datasets D1, D2 and D12 ([`cross_validate`]). What `hil workload select`
/// and hil-py's `select_workload` run, and what the bundled models are
/// chosen by.
///
/// ```
/// use hil_workload::{datasets::DatasetId, select::*, synth::SynthConfig};
/// let study = SynthConfig::small(8, 4).generate(1).unwrap();
/// let opts = SelectOptions { histories: vec![1], ..SelectOptions::default() };
/// let table = select_study_models(&study, &opts).unwrap();
/// for id in DatasetId::ALL {
///     assert!(table.best(id).is_some());
/// }
/// ```
pub fn select_study_models(
    study: &crate::study::Study,
    opts: &SelectOptions,
) -> Result<SelectionTable> {
    select_among(&study_datasets(study)?, opts)
}

/// Every candidate of the paper's table (with `opts.histories`) scored on
/// each of `sets` ([`cross_validate`]).
pub(crate) fn select_among(sets: &[Dataset], opts: &SelectOptions) -> Result<SelectionTable> {
    let refs: Vec<&Dataset> = sets.iter().collect();
    cross_validate(&refs, &Candidate::table(&opts.histories), opts)
}

/// The datasets D1, D2 and D12 of `study`, in [`DatasetId::ALL`] order.
pub fn study_datasets(study: &crate::study::Study) -> Result<Vec<Dataset>> {
    DatasetId::ALL
        .iter()
        .map(|&id| Dataset::build(study, id))
        .collect()
}

fn fmt_num(x: f64) -> String {
    if x.is_finite() && (1e-3..1e3).contains(&x.abs()) {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}

impl SelectionTable {
    /// The row of `cand` on `dataset`.
    pub fn row(&self, dataset: DatasetId, cand: Candidate) -> Option<&ScoreRow> {
        self.rows
            .iter()
            .find(|r| r.dataset == dataset && r.candidate == cand)
    }

    /// The winner on `dataset`: lowest median test MSE. Medians equal to
    /// within 1e-9 (relative) are ties, broken by the lower mean, then by
    /// table order (simpler models come first), so rounding noise between
    /// equivalent fits does not flip the choice.
    pub fn best(&self, dataset: DatasetId) -> Option<&ScoreRow> {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        let mut best: Option<&ScoreRow> = None;
        for r in self.rows.iter().filter(|r| r.dataset == dataset) {
            best = match best {
                None => Some(r),
                Some(b) if close(r.median, b.median) => {
                    if r.mean < b.mean && !close(r.mean, b.mean) {
                        Some(r)
                    } else {
                        Some(b)
                    }
                }
                Some(b) if r.median < b.median => Some(r),
                keep => keep,
            };
        }
        best
    }

    fn datasets(&self) -> Vec<DatasetId> {
        self.n_pairs.iter().map(|(d, _)| *d).collect()
    }

    fn candidates(&self) -> Vec<Candidate> {
        let mut v: Vec<Candidate> = Vec::new();
        for r in &self.rows {
            if !v.contains(&r.candidate) {
                v.push(r.candidate);
            }
        }
        v
    }

    /// Writes the table as `selection.md`, `selection.csv` and
    /// `selection.json` into `dir` (created if needed); returns their paths.
    pub fn write_to(&self, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>> {
        let files = [
            ("selection.md", self.to_markdown()),
            ("selection.csv", self.to_csv()),
            ("selection.json", self.to_json()),
        ];
        let mut written = Vec::new();
        for (name, text) in files {
            let path = dir.join(name);
            hil_core::files::write_text(&path, &text)?;
            written.push(path);
        }
        Ok(written)
    }

    /// The table in Markdown (bold: the winner per dataset).
    pub fn to_markdown(&self) -> String {
        let ds = self.datasets();
        let mut s = String::new();
        s.push_str("| Model | H |");
        for d in &ds {
            let _ = write!(
                s,
                " {} MSE (μ ± σ) | {} MSE (median) |",
                d.as_str().to_uppercase(),
                d.as_str().to_uppercase()
            );
        }
        s.push_str("\n|---|---|");
        for _ in &ds {
            s.push_str("---|---|");
        }
        s.push('\n');
        for c in self.candidates() {
            let _ = write!(
                s,
                "| {} | {} |",
                c.label(),
                c.history().map_or("-".into(), |h| h.to_string())
            );
            for &d in &ds {
                match self.row(d, c) {
                    Some(r) => {
                        let best = self.best(d).is_some_and(|b| b.candidate == c);
                        let med = fmt_num(r.median);
                        let med = if best { format!("**{med}**") } else { med };
                        let _ = write!(s, " {} ± {} | {med} |", fmt_num(r.mean), fmt_num(r.std));
                    }
                    None => s.push_str(" | |"),
                }
            }
            s.push('\n');
        }
        s.push_str("\nPairs: ");
        s.push_str(
            &self
                .n_pairs
                .iter()
                .map(|(d, n)| format!("{} = {n}", d.as_str().to_uppercase()))
                .collect::<Vec<_>>()
                .join(", "),
        );
        s.push_str(". Test MSE over outer folds; σ is the population standard deviation; predictions clamped to [0, 1].\n");
        s
    }

    /// One CSV line per (dataset, candidate).
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "dataset,model,history,mean_mse,std_mse,median_mse,fold_mse,fold_lambda,selected\n",
        );
        for r in &self.rows {
            let sel = self
                .best(r.dataset)
                .is_some_and(|b| b.candidate == r.candidate);
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{}",
                r.dataset.as_str(),
                r.candidate.label(),
                r.candidate
                    .history()
                    .map_or(String::new(), |h| h.to_string()),
                r.mean,
                r.std,
                r.median,
                r.fold_mse
                    .iter()
                    .map(|x| x.to_string())
                    .collect::<Vec<_>>()
                    .join(";"),
                r.fold_lambda
                    .iter()
                    .map(|x| x.map_or(String::new(), |l| l.to_string()))
                    .collect::<Vec<_>>()
                    .join(";"),
                sel
            );
        }
        s
    }

    /// The whole result as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("tables always serialise")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_candidate_parses_back_from_its_key() {
        let sim = Candidate::parse("granger_sim", None).unwrap();
        for cand in Candidate::table(&[1, 5]).into_iter().chain([sim]) {
            assert_eq!(Candidate::parse(cand.key(), cand.history()).unwrap(), cand);
        }
    }

    /// A history outside `1..=limits::HISTORY` is refused before a design of
    /// 9·H + 2 columns is allocated (H = 100 000 asked for terabytes).
    #[test]
    fn histories_outside_the_limit_are_refused_naming_them() {
        let name = |e: HilError| match e {
            HilError::InvalidParameter { name, .. } => name,
            other => panic!("{other:?}"),
        };
        for h in [None, Some(0), Some(361), Some(usize::MAX)] {
            let e = Candidate::parse("granger", h).unwrap_err();
            assert_eq!(name(e), "history");
        }
        assert!(Candidate::parse("granger", Some(360)).is_ok());
        assert_eq!(
            name(Candidate::parse("constant", Some(5)).unwrap_err()),
            "history"
        );
        // However a candidate is made, fitting checks it first.
        let big = Candidate::Granger {
            variant: GrangerVariant::Plain,
            h: 100_000,
        };
        assert_eq!(name(big.validate().unwrap_err()), "history");
        let opts = |histories: Vec<usize>| SelectOptions {
            histories,
            ..SelectOptions::default()
        };
        assert_eq!(
            name(opts(vec![1, 100_000]).validate().unwrap_err()),
            "histories[1]"
        );
        assert_eq!(name(opts(vec![0]).validate().unwrap_err()), "histories[0]");
        assert_eq!(name(opts(vec![]).validate().unwrap_err()), "histories");
        assert!(opts(vec![1, 30]).validate().is_ok());
    }
}
