//! Success rates per (food, action) over randomised trials, beside the
//! published rates (Feng et al. 2019), overall and per placement setting.
//!
//! Trials cycle through the settings (trial `t` uses `settings[t % n]`), so
//! 30 trials over the three settings are 10 per setting, as in the
//! published data set, and the overall rate compares with its `all` row.
//! Attempts run on `threads` worker threads (a [`hil_jobs::Runner`]), each
//! with its own simulators;
//! every attempt's seed depends only on (seed, food, action, trial), so the
//! result does not depend on the number of threads.
//!
//! ```
//! use hil_kinova_mujoco::{CalibrationOptions, calibrate_with};
//! use hil_kinova_mujoco::{FoodKind, Setting};
//!
//! let opts = CalibrationOptions {
//!     foods: vec![FoodKind::Carrot],
//!     settings: vec![Setting::Isolated],
//!     trials: 1,
//!     ..CalibrationOptions::default()
//! };
//! let report = calibrate_with(&opts, &|_, _| {}, &mut |_| {})?;
//! assert_eq!(report.rows.len(), 6);
//! // VS90 on carrot: published 1.0 when isolated (0.53 over all settings).
//! assert_eq!(report.rows[1].by_setting[0].published, Some(1.0));
//! assert_eq!(report.rows[1].published, Some(1.0));
//! assert_eq!(report.rows[1].counts.trials, 1);
//! # Ok::<(), hil_core::HilError>(())
//! ```

use std::collections::HashMap;
use std::path::PathBuf;

use std::time::{Duration, Instant};

use hil_core::{ArmId, Environment, HilError, Result};
use hil_jobs::Runner;
use hil_paper::food_data::{HOLD_SECONDS, TRIALS_PER_SETTING};
use hil_stats::{
    Alternative, Stat, binomial_pmf, binomial_se, binomial_upper_tail, bonferroni, convolve,
    fisher_exact,
};
use serde::Serialize;

use crate::controller::{RollBy, actions};
use crate::env::{KinovaFeedingConfig, KinovaFeedingEnv};
use crate::food::{FoodKind, Setting};
use crate::food_models::FoodModels;
use crate::sim::AttemptReport;

/// What to calibrate.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationOptions {
    /// Foods to run.
    pub foods: Vec<FoodKind>,
    /// Settings the trials cycle through.
    pub settings: Vec<Setting>,
    /// Trials per (food, action).
    pub trials: usize,
    /// Master seed.
    pub seed: u64,
    /// Worker threads, each with its own simulators ([`Runner::new`]: 0 =
    /// one per core, or `RAYON_NUM_THREADS`).
    pub threads: usize,
    /// The tool. Default [`RollBy::ArmYaw`]: the rigid fork the published
    /// rates were measured with (Feng et al. 2019), so that only the food
    /// model is compared; [`RollBy::ForkGamma`] runs the study robot's 2-DoF
    /// fork on the same foods.
    pub roll_by: RollBy,
    /// A food-models file changing the built-in food mechanics
    /// ([`FoodModels`]); `None` runs the built-in, calibrated ones.
    pub food_models: Option<PathBuf>,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        Self {
            foods: FoodKind::SCENE.to_vec(),
            settings: Setting::ALL.to_vec(),
            trials: 30,
            seed: 1,
            threads: 1,
            roll_by: RollBy::ArmYaw,
            food_models: None,
        }
    }
}

/// One (food, action) cell in one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SettingCell {
    /// The setting.
    pub setting: Setting,
    /// Trials, discards, successes, and the achieved rate with its SE.
    #[serde(flatten)]
    pub counts: Tally,
    /// Published rate in this setting.
    pub published: Option<f64>,
    /// How likely a difference this large is by chance alone: Fisher's
    /// exact two-sided test that the counted attempts here and the
    /// published ones ([`TRIALS_PER_SETTING`]) share one success
    /// rate. `None` when no attempt counted.
    pub p_value: Option<f64>,
}

/// One (food, action) cell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationRow {
    /// Food.
    pub food: String,
    /// Action label.
    pub action: String,
    /// Trials, discards, successes, and the achieved rate with its SE.
    #[serde(flatten)]
    pub counts: Tally,
    /// Published rate (setting `all`) when the trials cover all three
    /// settings equally; otherwise the mean of the published rates of the
    /// settings run.
    pub published: Option<f64>,
    /// The same cell per setting.
    pub by_setting: Vec<SettingCell>,
    /// As [`SettingCell::p_value`], over the row's settings together (the
    /// published successes of each setting summed).
    pub p_value: Option<f64>,
}

/// One simulated attempt, for the attempt log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AttemptRecord {
    /// Food.
    pub food: FoodKind,
    /// Setting.
    pub setting: Setting,
    /// Trial index within the (food, action) cell.
    pub trial: usize,
    /// Seed the environment was reset with.
    pub seed: u64,
    /// What the simulation measured.
    pub report: AttemptReport,
}

/// The calibration table and throughput.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationReport {
    /// One row per (food, action).
    pub rows: Vec<CalibrationRow>,
    /// Mean absolute difference to the published rates (overall rows).
    pub mean_abs_error: f64,
    /// Largest absolute difference to the published rates (overall rows).
    pub max_abs_error: f64,
    /// Mean absolute difference per setting cell.
    pub mean_abs_error_by_setting: f64,
    /// The mean absolute difference a *perfect* simulator would be expected
    /// to show over the same overall rows: one whose true rate in every
    /// setting is the published one, so that only the sampling noise of
    /// both tables remains (the published cells rest on
    /// [`TRIALS_PER_SETTING`] trials per setting; the simulated
    /// ones on the trials counted here). The floor `mean_abs_error` is to
    /// be read against.
    pub noise_floor: f64,
    /// The largest |simulated − published| over the overall rows that the
    /// perfect simulator of `noise_floor` is expected to show: what the
    /// worst cell (`max_abs_error`) is to be read against.
    pub noise_floor_worst_cell: f64,
    /// The acceptance this table is read against.
    pub target: CalibrationTarget,
    /// Whether this run meets [`target`](Self::target).
    pub meets_target: bool,
    /// The probability that a perfect simulator (as for `noise_floor`)
    /// meets [`target`](Self::target) in one run with these trial counts:
    /// how often a run *can* meet it, whatever the model.
    pub perfect_simulator_meets_target: f64,
    /// How the overall rows stand against the published ones by the
    /// p-values of [`CalibrationRow::p_value`]: whether any difference is
    /// larger than the sampling noise of both tables explains.
    pub consistency: Consistency,
    /// The same over the per-setting cells.
    pub consistency_by_setting: Consistency,
    /// How long an item had to stay on the lifted fork (s).
    pub hold_s: f64,
    /// What turned the tine row by the actions' roll.
    pub roll_by: RollBy,
    /// The food-models file the run used instead of the built-in models,
    /// if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub food_models: Option<FoodModelsUsed>,
    /// Physics steps per attempt (staging and execution), averaged.
    pub steps_per_attempt: f64,
    /// CPU time per physics step inside `mj_step` (µs), averaged (the CPU
    /// time apportioned by the wall-clock share inside `mj_step`): with
    /// `steps_per_attempt` this bounds the attempts per second per core.
    pub micros_per_step: f64,
    /// Simulated attempts per wall-clock second, all threads together.
    pub attempts_per_second: f64,
    /// Simulated attempts per second of one core: attempts over the CPU
    /// time the worker threads spent on them (other programs on the
    /// machine do not count against it).
    pub attempts_per_second_per_core: f64,
    /// Worker threads used.
    pub threads: usize,
    /// Share of the attempts' time spent outside `mj_step`.
    pub overhead_share: f64,
    /// Provenance note.
    pub note: &'static str,
}

/// A food-models file a run used, and the kinds it changed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FoodModelsUsed {
    /// The file.
    pub path: PathBuf,
    /// The kinds whose models it changed.
    pub changed: Vec<FoodKind>,
}

/// Runs `trials` randomised attempts of every action on every food over all
/// three settings, on one thread.
pub fn calibrate(trials: usize, seed: u64) -> Result<CalibrationReport> {
    calibrate_with(
        &CalibrationOptions {
            trials,
            seed,
            ..CalibrationOptions::default()
        },
        &|_, _| {},
        &mut |_| {},
    )
}

/// The seed of trial `trial` of `action` on `food`.
pub fn trial_seed(seed: u64, food: FoodKind, action: usize, trial: usize) -> u64 {
    seed.wrapping_mul(1_000_003)
        .wrapping_add((food.index() * 6 + action) as u64 * 10_007 + trial as u64)
}

/// Runs the calibration described by `opts`, reporting progress
/// `(done, total)` from the worker threads and every attempt, in job order,
/// to `log`.
pub fn calibrate_with(
    opts: &CalibrationOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    log: &mut dyn FnMut(&AttemptRecord),
) -> Result<CalibrationReport> {
    if opts.foods.is_empty() || opts.settings.is_empty() || opts.trials == 0 {
        return Err(HilError::invalid_parameter(
            "calibration",
            format!(
                "{} foods, {} settings, {} trials",
                opts.foods.len(),
                opts.settings.len(),
                opts.trials,
            ),
            "needs at least one of each",
        ));
    }
    hil_config::limits::check_count("trials", opts.trials, hil_config::limits::TRIALS)?;
    // A bad food-models file fails here, before any attempt runs.
    let models = FoodModels::from_file(opts.food_models.as_deref())?;
    let food_models = opts.food_models.as_ref().map(|path| FoodModelsUsed {
        path: path.clone(),
        changed: models.changed(),
    });
    let start = Instant::now();
    let jobs: Vec<(FoodKind, usize, usize)> = opts
        .foods
        .iter()
        .flat_map(|&f| {
            (0..actions().len()).flat_map(move |a| (0..opts.trials).map(move |t| (f, a, t)))
        })
        .collect();
    let total = jobs.len();
    let runner = Runner::new(opts.threads)?;
    // One set of simulators per worker thread, kept across its jobs
    // (building a MuJoCo scene costs far more than an attempt).
    type Scenes = HashMap<(FoodKind, Setting), KinovaFeedingEnv>;
    let attempt =
        |envs: &mut Scenes, &(food, a, t): &(FoodKind, usize, usize)| -> Result<AttemptRecord> {
            let setting = opts.settings[t % opts.settings.len()];
            let env = match envs.entry((food, setting)) {
                std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                std::collections::hash_map::Entry::Vacant(e) => {
                    // The models read once above; the config still names
                    // the file, as the scene it describes uses it.
                    let scene = KinovaFeedingConfig {
                        plate: vec![food.name().to_string()],
                        settings: vec![setting.name().to_string()],
                        roll_by: opts.roll_by,
                        food_models: opts.food_models.clone(),
                        ..KinovaFeedingConfig::default()
                    };
                    e.insert(KinovaFeedingEnv::with_models(scene, models.clone())?)
                }
            };
            let seed = trial_seed(opts.seed, food, a, t);
            env.reset(seed)?;
            env.next_item()?;
            env.observe()?;
            env.execute(ArmId(a))?;
            let report = env
                .last_attempt()
                .cloned()
                .ok_or_else(|| HilError::state("kinova calibrate", "an attempt left no report"))?;
            Ok(AttemptRecord {
                food,
                setting,
                trial: t,
                seed,
                report,
            })
        };
    // Records come back in job order; the first error stops the run.
    let (records, scenes) = runner.map_per_worker(&jobs, Scenes::new, attempt, progress)?;
    let mut timing = (Duration::ZERO, Duration::ZERO);
    let mut cpu = Duration::ZERO;
    let mut steps = 0u64;
    let mut hold_s = HOLD_SECONDS;
    for envs in &scenes {
        for env in envs.values() {
            let t = env.simulator().timing();
            timing.0 += t.in_step;
            timing.1 += t.total;
            steps += t.steps;
            cpu += t.cpu;
            hold_s = env.simulator().hold();
        }
    }
    let wall = start.elapsed().as_secs_f64();
    for r in &records {
        log(r);
    }
    let rows = tabulate(opts, &records);
    let (in_step, busy) = timing;
    // 0 when no cell has a published rate to compare with.
    let mean = |v: Vec<f64>| {
        if v.is_empty() {
            0.0
        } else {
            hil_stats::mean(&v)
        }
    };
    // The overall rows that have a published rate to compare with.
    let compared: Vec<&CalibrationRow> = rows.iter().filter(|r| r.published.is_some()).collect();
    let errors: Vec<f64> = compared
        .iter()
        .filter_map(|r| r.published.map(|p| (p - r.counts.rate).abs()))
        .collect();
    let max_abs_error = errors.iter().copied().fold(0.0, f64::max);
    let mean_abs_error = mean(errors);
    let noise_floor = mean(
        compared
            .iter()
            .map(|r| expected_abs_error_of_a_perfect_simulator(r))
            .collect(),
    );
    let target = CalibrationTarget::ACCEPTANCE;
    let (consistency, consistency_by_setting) = consistency_of(&rows);
    let noise_floor_worst_cell = expected_worst_error_of_a_perfect_simulator(&compared);
    Ok(CalibrationReport {
        noise_floor_worst_cell,
        consistency,
        consistency_by_setting,
        noise_floor,
        target,
        meets_target: target.is_met(mean_abs_error, max_abs_error),
        perfect_simulator_meets_target: target.chance_a_perfect_simulator_meets(&compared),
        max_abs_error,
        hold_s,
        roll_by: opts.roll_by,
        food_models,
        steps_per_attempt: steps as f64 / total.max(1) as f64,
        micros_per_step: 1e6
            * cpu.as_secs_f64()
            * (in_step.as_secs_f64() / busy.as_secs_f64().max(1e-9))
            / steps.max(1) as f64,
        mean_abs_error,
        mean_abs_error_by_setting: mean(
            rows.iter()
                .flat_map(|r| &r.by_setting)
                .filter_map(|c| c.published.map(|p| (p - c.counts.rate).abs()))
                .collect(),
        ),
        attempts_per_second: total as f64 / wall.max(1e-9),
        attempts_per_second_per_core: total as f64 / cpu.as_secs_f64().max(1e-9),
        threads: runner.threads(),
        overhead_share: 1.0 - in_step.as_secs_f64() / busy.as_secs_f64().max(1e-9),
        rows,
        note: "simulated (MuJoCo) attempts with synthetic food properties; published rates: Feng et al. 2019 (settings isolated, wall, lettuce; `all` is their mean)",
    })
}

/// The expected |simulated − published| of `row` for a simulator whose
/// true rate in every setting equals the published one: the overall
/// published rate is the sum of [`TRIALS_PER_SETTING`]-trial
/// binomials over the row's settings, the simulated one the sum of
/// binomials over the trials counted per setting; both distributions are
/// enumerated exactly.
pub fn expected_abs_error_of_a_perfect_simulator(row: &CalibrationRow) -> f64 {
    perfect_simulator_errors(row)
        .iter()
        .map(|(e, p)| e * p)
        .sum()
}

/// The expected largest |simulated − published| over `rows` for a
/// perfect simulator (see [`expected_abs_error_of_a_perfect_simulator`]):
/// the cells are independent, so the largest error is at most `x` with
/// the product of the cells' probabilities of being at most `x`; errors
/// are binned to 1/[`TARGET_GRID`] as in
/// [`CalibrationTarget::chance_a_perfect_simulator_meets`].
pub fn expected_worst_error_of_a_perfect_simulator(rows: &[&CalibrationRow]) -> f64 {
    let bins = TARGET_GRID as usize;
    // cdf[b]: probability that every cell so far is within b bins.
    let mut cdf = vec![1.0; bins + 1];
    for row in rows {
        let mut cell = vec![0.0; bins + 1];
        for (e, p) in perfect_simulator_errors(row) {
            cell[error_bin(e).min(bins)] += p;
        }
        let mut within = 0.0;
        for (b, c) in cdf.iter_mut().enumerate() {
            within += cell[b];
            *c *= within;
        }
    }
    // E[max] = Σ_b b·P(max = b bins), P(max = b) = cdf[b] − cdf[b − 1].
    (1..=bins)
        .map(|b| b as f64 / TARGET_GRID * (cdf[b] - cdf[b - 1]))
        .sum()
}

/// The distribution of |simulated − published| of `row` for a perfect
/// simulator (see [`expected_abs_error_of_a_perfect_simulator`]): every
/// (published count, simulated count) pair as (|error|, probability).
fn perfect_simulator_errors(row: &CalibrationRow) -> Vec<(f64, f64)> {
    let sum_of = |trials: &dyn Fn(&SettingCell) -> usize| -> Vec<f64> {
        row.by_setting.iter().fold(vec![1.0], |dist, c| {
            convolve(&dist, &binomial_pmf(trials(c), c.published.unwrap_or(0.0)))
        })
    };
    let published = sum_of(&|_| TRIALS_PER_SETTING);
    let simulated = sum_of(&|c| c.counts.trials - c.counts.discarded);
    let (np, ns) = (published.len() - 1, simulated.len() - 1);
    if np == 0 || ns == 0 {
        return vec![(0.0, 1.0)];
    }
    let mut out = Vec::with_capacity(published.len() * simulated.len());
    for (i, pi) in published.iter().enumerate() {
        for (j, pj) in simulated.iter().enumerate() {
            out.push(((i as f64 / np as f64 - j as f64 / ns as f64).abs(), pi * pj));
        }
    }
    out
}

/// The acceptance a calibration run is read against: the mean
/// |simulated − published| over the overall cells and the largest one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CalibrationTarget {
    /// Largest acceptable mean |simulated − published| over the cells.
    pub mean_abs_error: f64,
    /// Largest acceptable |simulated − published| of any one cell.
    pub worst_cell: f64,
}

impl CalibrationTarget {
    /// The project's acceptance for the Kinova simulation: mean ≤ 0.06
    /// and no cell off by more than 0.15 (at ≥ 60 trials per cell).
    pub const ACCEPTANCE: CalibrationTarget = CalibrationTarget {
        mean_abs_error: 0.06,
        worst_cell: 0.15,
    };

    /// Whether a run with this mean and largest error meets the target
    /// (to within rounding: an error of exactly 0.15 is not above 0.15).
    pub fn is_met(&self, mean_abs_error: f64, max_abs_error: f64) -> bool {
        mean_abs_error <= self.mean_abs_error + TARGET_TOLERANCE
            && max_abs_error <= self.worst_cell + TARGET_TOLERANCE
    }

    /// The probability that one run of a perfect simulator over `rows`
    /// (their settings and counted trials) meets the target: the cells'
    /// errors are independent, so the chance that every cell is within
    /// `worst_cell` *and* their sum within `mean_abs_error · rows` is
    /// their distributions (restricted to `worst_cell`) convolved, with
    /// errors binned to 1/[`TARGET_GRID`] (exact when the published and
    /// simulated trials per cell both divide it: 30 against 60, 90 or 120).
    ///
    /// ```
    /// use hil_kinova_mujoco::{CalibrationOptions, CalibrationTarget, calibrate_with};
    /// use hil_kinova_mujoco::{FoodKind, Setting};
    ///
    /// let opts = CalibrationOptions {
    ///     foods: vec![FoodKind::Banana],
    ///     settings: vec![Setting::Isolated],
    ///     trials: 1,
    ///     ..CalibrationOptions::default()
    /// };
    /// let report = calibrate_with(&opts, &|_, _| {}, &mut |_| {})?;
    /// let rows: Vec<_> = report.rows.iter().collect();
    /// let p = CalibrationTarget::ACCEPTANCE.chance_a_perfect_simulator_meets(&rows);
    /// // One trial per cell against 10 published ones: rarely within target.
    /// assert!(p > 0.0 && p < 0.2, "{p}");
    /// assert_eq!(p, report.perfect_simulator_meets_target);
    /// # Ok::<(), hil_core::HilError>(())
    /// ```
    pub fn chance_a_perfect_simulator_meets(&self, rows: &[&CalibrationRow]) -> f64 {
        let worst = error_bin(self.worst_cell);
        let budget = error_bin(self.mean_abs_error * rows.len() as f64);
        // dist[s]: probability that the cells so far are each within
        // `worst` and sum to s bins (sums beyond the budget fail).
        let mut dist = vec![0.0; budget + 1];
        dist[0] = 1.0;
        for row in rows {
            let mut cell = vec![0.0; worst + 1];
            for (e, p) in perfect_simulator_errors(row) {
                if let Some(c) = cell.get_mut(error_bin(e)) {
                    *c += p;
                }
            }
            let mut next = vec![0.0; budget + 1];
            for (s, ps) in dist.iter().enumerate().filter(|(_, p)| **p > 0.0) {
                for (b, pb) in cell.iter().enumerate().take(budget + 1 - s) {
                    next[s + b] += ps * pb;
                }
            }
            dist = next;
        }
        dist.iter().sum()
    }
}

/// Bins per unit of error in [`CalibrationTarget::chance_a_perfect_simulator_meets`].
pub const TARGET_GRID: f64 = 3600.0;
/// The bin of an error on the 1/[`TARGET_GRID`] grid.
fn error_bin(e: f64) -> usize {
    (e * TARGET_GRID).round() as usize
}

/// Rounding allowance when comparing an error with a target.
const TARGET_TOLERANCE: f64 = 1e-9;

/// Fisher's exact two-sided p-value that the counted attempts of `t` and
/// the published attempts behind `published` (one rate per setting, each
/// over [`TRIALS_PER_SETTING`] trials) share one success rate;
/// `None` when no attempt counted or nothing was published (the test has
/// no sample then).
fn consistency_p(t: &Tally, published: &[f64]) -> Option<f64> {
    let n = TRIALS_PER_SETTING as f64;
    // A published rate is a count over its trials (0.4 = 4 of 10).
    let successes: u64 = published.iter().map(|p| (p * n).round() as u64).sum();
    let trials = (TRIALS_PER_SETTING * published.len()) as u64;
    let counted = (t.trials - t.discarded) as u64;
    fisher_exact(
        t.successes as u64,
        counted,
        successes,
        trials,
        Alternative::TwoSided,
    )
    .ok()
    .map(|r| r.p_value)
}

/// [`consistency_p`] of a row's tally against the published rates of its
/// setting cells.
fn row_p_value(t: &Tally, cells: &[SettingCell]) -> Option<f64> {
    let published: Vec<f64> = cells.iter().filter_map(|c| c.published).collect();
    consistency_p(t, &published)
}

/// Whether a table's differences from the published one exceed what the
/// sampling noise of both explains: the per-cell p-values of Fisher's exact
/// test (see [`CalibrationRow::p_value`]) summarised.
///
/// Read it with the multiplicity in mind: among 18 cells of a simulator
/// whose every rate is the published one, about one in twenty would fall
/// below 0.05 by chance (fewer: tests on counts are conservative).
/// `smallest_p_adjusted` accounts for that.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Consistency {
    /// Cells tested (those with counted attempts).
    pub cells: usize,
    /// Cells whose p-value is below 0.05.
    pub below_0_05: usize,
    /// The cell with the smallest p-value (`carrot VS90`, or
    /// `carrot VS90 lettuce` per setting); empty when no cell was tested.
    pub least_consistent: String,
    /// Its p-value.
    pub smallest_p: f64,
    /// The smallest p-value times the number of cells, at most 1
    /// (Bonferroni): at most this likely is a cell this far off anywhere
    /// in the table if every simulated rate were the published one.
    pub smallest_p_adjusted: f64,
    /// At most this likely are `below_0_05` or more such cells if every
    /// simulated rate were the published one: the cells are independent
    /// and each falls below 0.05 with probability at most 0.05, so their
    /// count is at most a binomial(cells, 0.05) one. Small when the table
    /// differs in many cells, none of them decisively.
    pub p_this_many_below_0_05: f64,
    /// Every cell below 0.05 with its p-value, most surprising first: what
    /// still differs from the published table, named.
    pub cells_below_0_05: Vec<CellP>,
}

/// One cell's label and p-value ([`Consistency::cells_below_0_05`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellP {
    /// The cell (`carrot VS90 lettuce`).
    pub cell: String,
    /// Its p-value.
    pub p: f64,
}

impl Consistency {
    /// Summarises labelled p-values (`None`: the cell was not tested).
    pub fn over(cells: impl IntoIterator<Item = (String, Option<f64>)>) -> Self {
        let tested: Vec<(String, f64)> = cells
            .into_iter()
            .filter_map(|(label, p)| p.map(|p| (label, p)))
            .collect();
        let (least_consistent, smallest_p) = tested
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .cloned()
            .unwrap_or((String::new(), 1.0));
        let mut cells_below_0_05: Vec<CellP> = tested
            .iter()
            .filter(|(_, p)| *p < 0.05)
            .map(|(cell, p)| CellP {
                cell: cell.clone(),
                p: *p,
            })
            .collect();
        // Stable: equal p-values keep the table's order.
        cells_below_0_05.sort_by(|a, b| a.p.total_cmp(&b.p));
        let below_0_05 = cells_below_0_05.len();
        Consistency {
            cells: tested.len(),
            below_0_05,
            cells_below_0_05,
            p_this_many_below_0_05: binomial_upper_tail(tested.len(), 0.05, below_0_05),
            least_consistent,
            smallest_p,
            smallest_p_adjusted: bonferroni(smallest_p, tested.len()),
        }
    }
}

/// Trials, discarded trials and successes among some attempts, and the
/// success rate over those that counted with its binomial SE.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tally {
    /// Trials run.
    pub trials: usize,
    /// Trials discarded under the published rule (fewer than
    /// [`MIN_TINES_TOUCHED`](crate::MIN_TINES_TOUCHED) tines touched the item).
    pub discarded: usize,
    /// Successes.
    pub successes: usize,
    /// Achieved success rate over the trials that counted.
    pub rate: f64,
    /// Binomial standard error of `rate`, √(p(1−p)/n).
    pub se: f64,
}

/// Tallies `records`: an attempt in which fewer than
/// [`MIN_TINES_TOUCHED`](crate::MIN_TINES_TOUCHED) tines touched the item
/// is discarded, as in the published data set, and counts neither way.
fn count(records: &[&&AttemptRecord]) -> Tally {
    let discarded = records.iter().filter(|r| !r.report.counted).count();
    let successes = records
        .iter()
        .filter(|r| r.report.counted && r.report.success)
        .count();
    Tally::of(records.len(), discarded, successes)
}

impl Tally {
    /// The rate over the `trials − discarded` that counted, and its SE.
    fn of(trials: usize, discarded: usize, successes: usize) -> Self {
        let counted = trials - discarded;
        Tally {
            trials,
            discarded,
            successes,
            rate: successes as f64 / counted.max(1) as f64,
            se: binomial_se(successes, counted),
        }
    }
}

/// The [`Consistency`] of the overall rows and of the per-setting cells.
fn consistency_of(rows: &[CalibrationRow]) -> (Consistency, Consistency) {
    let overall = Consistency::over(
        rows.iter()
            .map(|r| (format!("{} {}", r.food, r.action), r.p_value)),
    );
    let by_setting = Consistency::over(rows.iter().flat_map(|r| {
        r.by_setting.iter().map(move |c| {
            (
                format!("{} {} {}", r.food, r.action, c.setting.name()),
                c.p_value,
            )
        })
    }));
    (overall, by_setting)
}

/// Calibration runs under several master seeds: the spread of one run's
/// figures (how a single run reads against the acceptance) and every
/// run's attempts pooled (how the simulator itself does, with the
/// simulated side's noise shrunk by the number of runs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationOverSeeds {
    /// The master seeds, one run each.
    pub seeds: Vec<u64>,
    /// Mean |simulated − published| over the overall cells: mean, SD and
    /// standard error over the runs.
    pub mean_abs_error: Stat,
    /// The worst cell's |simulated − published|, over the runs.
    pub max_abs_error: Stat,
    /// [`CalibrationReport::noise_floor`] averaged over the runs: what
    /// `mean_abs_error` is to be read against.
    pub noise_floor: f64,
    /// [`CalibrationReport::noise_floor_worst_cell`] averaged over the
    /// runs: what `max_abs_error` is to be read against.
    pub noise_floor_worst_cell: f64,
    /// The acceptance the runs are read against.
    pub target: CalibrationTarget,
    /// Runs that meet [`target`](Self::target).
    pub runs_meeting_target: usize,
    /// The chance that one run of a perfect simulator with the same trial
    /// counts meets it, averaged over the runs (the counts differ only by
    /// discarded attempts).
    pub perfect_simulator_meets_target: f64,
    /// Every run's attempts together, per (food, action) and setting, with
    /// their p-values against the published counts.
    pub pooled: Vec<CalibrationRow>,
    /// [`Consistency`] of the pooled overall rows.
    pub pooled_consistency: Consistency,
    /// [`Consistency`] of the pooled per-setting cells.
    pub pooled_consistency_by_setting: Consistency,
    /// The runs, in seed order.
    pub runs: Vec<CalibrationReport>,
}

/// Runs [`calibrate_with`] once per seed in `seeds` (`opts.seed` is
/// ignored) and summarises the runs; `progress` gets `(run, done, total)`.
pub fn calibrate_over_seeds(
    opts: &CalibrationOptions,
    seeds: &[u64],
    progress: &(dyn Fn(usize, usize, usize) + Sync),
    log: &mut dyn FnMut(&AttemptRecord),
) -> Result<CalibrationOverSeeds> {
    if seeds.is_empty() {
        return Err(HilError::invalid_parameter(
            "seeds",
            "[]",
            "needs at least one seed",
        ));
    }
    let mut runs = Vec::with_capacity(seeds.len());
    for (i, &seed) in seeds.iter().enumerate() {
        let run_opts = CalibrationOptions {
            seed,
            ..opts.clone()
        };
        runs.push(calibrate_with(&run_opts, &|d, t| progress(i, d, t), log)?);
    }
    Ok(summarise_runs(seeds.to_vec(), runs))
}

/// The summary of runs of one calibration under different seeds.
fn summarise_runs(seeds: Vec<u64>, runs: Vec<CalibrationReport>) -> CalibrationOverSeeds {
    let of =
        |f: &dyn Fn(&CalibrationReport) -> f64| Stat::of(&runs.iter().map(f).collect::<Vec<_>>());
    let pooled = pool_rows(&runs);
    let (pooled_consistency, pooled_consistency_by_setting) = consistency_of(&pooled);
    let target = CalibrationTarget::ACCEPTANCE;
    CalibrationOverSeeds {
        mean_abs_error: of(&|r| r.mean_abs_error),
        max_abs_error: of(&|r| r.max_abs_error),
        noise_floor: of(&|r| r.noise_floor).mean,
        noise_floor_worst_cell: of(&|r| r.noise_floor_worst_cell).mean,
        target,
        runs_meeting_target: runs.iter().filter(|r| r.meets_target).count(),
        perfect_simulator_meets_target: of(&|r| r.perfect_simulator_meets_target).mean,
        pooled,
        pooled_consistency,
        pooled_consistency_by_setting,
        seeds,
        runs,
    }
}

/// The rows of `runs` (same foods, actions and settings) with their counts
/// summed and rates, SEs and p-values recomputed.
fn pool_rows(runs: &[CalibrationReport]) -> Vec<CalibrationRow> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    let sum = |f: &dyn Fn(&CalibrationReport) -> (usize, usize, usize)| {
        runs.iter()
            .map(f)
            .fold((0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2))
    };
    first
        .rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let by_setting: Vec<SettingCell> = row
                .by_setting
                .iter()
                .enumerate()
                .map(|(j, cell)| {
                    let (n, d, s) = sum(&|r| {
                        let c = &r.rows[i].by_setting[j];
                        (c.counts.trials, c.counts.discarded, c.counts.successes)
                    });
                    let t = Tally::of(n, d, s);
                    SettingCell {
                        p_value: consistency_p(&t, cell.published.as_slice()),
                        counts: t,
                        ..cell.clone()
                    }
                })
                .collect();
            let (n, d, s) = sum(&|r| {
                (
                    r.rows[i].counts.trials,
                    r.rows[i].counts.discarded,
                    r.rows[i].counts.successes,
                )
            });
            let t = Tally::of(n, d, s);
            CalibrationRow {
                p_value: row_p_value(&t, &by_setting),
                counts: t,
                by_setting,
                ..row.clone()
            }
        })
        .collect()
}

/// Groups attempt records into rows per (food, action), in job order.
fn tabulate(opts: &CalibrationOptions, records: &[AttemptRecord]) -> Vec<CalibrationRow> {
    let mut rows = Vec::new();
    for &food in &opts.foods {
        for (a, action) in actions().iter().enumerate() {
            let cell: Vec<&AttemptRecord> = records
                .iter()
                .filter(|r| r.food == food && r.report.action == action.name)
                .collect();
            let by_setting: Vec<SettingCell> = opts
                .settings
                .iter()
                .map(|&setting| {
                    let here: Vec<&&AttemptRecord> =
                        cell.iter().filter(|r| r.setting == setting).collect();
                    let t = count(&here);
                    let published = food.published_rates_in(setting)[a];
                    SettingCell {
                        setting,
                        p_value: consistency_p(&t, &[published]),
                        counts: t,
                        published: Some(published),
                    }
                })
                .collect();
            let t = count(&cell.iter().collect::<Vec<_>>());
            // With all three settings equally represented the published
            // `all` row applies; otherwise the trial-weighted mean of the
            // settings run.
            let covers_all = Setting::ALL.iter().all(|s| opts.settings.contains(s))
                && by_setting
                    .iter()
                    .all(|c| c.counts.trials == by_setting[0].counts.trials);
            let published = if covers_all {
                Some(food.published_rates()[a])
            } else {
                Some(
                    by_setting
                        .iter()
                        .map(|c| food.published_rates_in(c.setting)[a] * c.counts.trials as f64)
                        .sum::<f64>()
                        / t.trials.max(1) as f64,
                )
            };
            rows.push(CalibrationRow {
                p_value: row_p_value(&t, &by_setting),
                food: food.name().into(),
                action: action.name.into(),
                counts: t,
                published,
                by_setting,
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::StopReason;
    use crate::skewer::SkewerStats;

    /// Trial counts outside `1..=limits::TRIALS` are refused before the
    /// job list is built (a 20-digit count was a capacity overflow).
    #[test]
    fn trial_counts_outside_the_limit_are_refused() {
        let quiet = |_: usize, _: usize| {};
        for trials in [0, hil_config::limits::TRIALS as usize + 1, usize::MAX] {
            let opts = CalibrationOptions {
                trials,
                ..CalibrationOptions::default()
            };
            let err = calibrate_with(&opts, &quiet, &mut |_| {}).unwrap_err();
            assert!(
                matches!(err, HilError::InvalidParameter { .. }),
                "{trials}: {err}"
            );
        }
    }

    fn record(setting: Setting, touched: usize, success: bool) -> AttemptRecord {
        AttemptRecord {
            food: FoodKind::Banana,
            setting,
            trial: 0,
            seed: 0,
            report: AttemptReport {
                action: actions()[0].name,
                food: FoodKind::Banana,
                success,
                reached_pitch: 0.0,
                reached_gamma: 0.0,
                reached_roll: 0.0,
                handle_roll: 0.0,
                stop: StopReason::Force,
                peak_force: 0.0,
                tines: SkewerStats {
                    touched,
                    ..SkewerStats::default()
                },
                tines_after_penetration: SkewerStats::default(),
                tines_after_lift: SkewerStats::default(),
                push_shift: 0.0,
                push_tilt: 0.0,
                counted: touched >= crate::sim::MIN_TINES_TOUCHED,
                final_height: 0.0,
                lifted_height: 0.0,
                hold_slip: 0.0,
                sim_time: 0.0,
                steps: 0,
            },
        }
    }

    #[test]
    fn a_perfect_simulator_still_differs_by_the_sampling_noise() {
        let row = one_setting_row;
        // Certain outcomes leave no noise.
        assert_eq!(
            expected_abs_error_of_a_perfect_simulator(&row(1.0, 20)),
            0.0
        );
        assert_eq!(
            expected_abs_error_of_a_perfect_simulator(&row(0.0, 20)),
            0.0
        );
        // p = 0.5, 10 published and 10 simulated trials: E|X - Y|/10 with
        // X - Y ~ 20-trial binomial shifted by 10, by enumeration.
        let exact: f64 = (0..=20usize)
            .map(|k| {
                let c = (1..=k).fold(1.0, |c, i| c * (20 - i + 1) as f64 / i as f64);
                c * 0.5f64.powi(20) * (k as f64 - 10.0).abs() / 10.0
            })
            .sum();
        let e = expected_abs_error_of_a_perfect_simulator(&row(0.5, 10));
        assert!((e - exact).abs() < 1e-12, "{e} vs {exact}");
        // More simulated trials shrink it, but not below the published noise.
        let more = expected_abs_error_of_a_perfect_simulator(&row(0.5, 1000));
        assert!(more < e && more > 0.1, "{more}");
    }

    /// A row of one setting whose counts are the cell's.
    fn one_setting_row(published: f64, trials: usize) -> CalibrationRow {
        let cell = SettingCell {
            setting: Setting::Isolated,
            counts: Tally::of(trials, 0, 0),
            published: Some(published),
            p_value: None,
        };
        CalibrationRow {
            food: "banana".into(),
            action: "VS0".into(),
            counts: cell.counts.clone(),
            published: cell.published,
            p_value: cell.p_value,
            by_setting: vec![cell],
        }
    }

    #[test]
    fn a_perfect_simulators_chance_of_meeting_the_target_is_the_joint_probability() {
        let target = CalibrationTarget {
            mean_abs_error: 0.1,
            worst_cell: 0.15,
        };
        // Certain outcomes always meet it.
        let certain = [one_setting_row(1.0, 20), one_setting_row(0.0, 20)];
        let p = target.chance_a_perfect_simulator_meets(&certain.iter().collect::<Vec<_>>());
        assert!((p - 1.0).abs() < 1e-12, "{p}");
        // Two noisy cells (10 published, 20 simulated trials; errors are
        // multiples of 1/20): both within 0.15 and together within 0.2,
        // by direct enumeration of the pairs of errors.
        let rows = [one_setting_row(0.5, 20), one_setting_row(0.3, 20)];
        let (a, b) = (
            perfect_simulator_errors(&rows[0]),
            perfect_simulator_errors(&rows[1]),
        );
        let mut exact = 0.0;
        for (ea, pa) in &a {
            for (eb, pb) in &b {
                if *ea <= 0.15 + 1e-9 && *eb <= 0.15 + 1e-9 && ea + eb <= 0.2 + 1e-9 {
                    exact += pa * pb;
                }
            }
        }
        let p = target.chance_a_perfect_simulator_meets(&rows.iter().collect::<Vec<_>>());
        assert!((p - exact).abs() < 1e-12, "{p} vs {exact}");
        // Both constraints bind: neither alone gives the joint chance.
        let cells_only: f64 = [&a, &b]
            .iter()
            .map(|d| {
                d.iter()
                    .filter(|(e, _)| *e <= 0.15 + 1e-9)
                    .map(|(_, p)| p)
                    .sum::<f64>()
            })
            .product();
        assert!(
            exact < cells_only - 0.01 && exact > 0.05,
            "{exact} {cells_only}"
        );
    }

    #[test]
    fn a_perfect_simulators_expected_worst_cell_is_the_mean_of_the_larger_error() {
        let rows = [one_setting_row(0.5, 20), one_setting_row(0.3, 20)];
        let (a, b) = (
            perfect_simulator_errors(&rows[0]),
            perfect_simulator_errors(&rows[1]),
        );
        let exact: f64 = a
            .iter()
            .flat_map(|(ea, pa)| b.iter().map(move |(eb, pb)| ea.max(*eb) * pa * pb))
            .sum();
        let e = expected_worst_error_of_a_perfect_simulator(&rows.iter().collect::<Vec<_>>());
        assert!((e - exact).abs() < 1e-9, "{e} vs {exact}");
        // The worst of two is above either cell's own mean error.
        let one = expected_abs_error_of_a_perfect_simulator(&rows[0]);
        assert!(e > one + 0.01, "{e} {one}");
        let certain = [one_setting_row(1.0, 20)];
        assert_eq!(
            expected_worst_error_of_a_perfect_simulator(&certain.iter().collect::<Vec<_>>()),
            0.0
        );
    }

    #[test]
    fn a_target_allows_an_error_equal_to_its_bound_and_nothing_above() {
        let t = CalibrationTarget::ACCEPTANCE;
        assert!(t.is_met(0.06, 0.15));
        assert!(t.is_met(0.03, 9.0 / 60.0));
        assert!(!t.is_met(0.0601, 0.1));
        assert!(!t.is_met(0.05, 0.1501));
    }

    #[test]
    fn attempts_with_fewer_than_two_tines_touching_are_discarded_not_failed() {
        let opts = CalibrationOptions {
            foods: vec![FoodKind::Banana],
            settings: vec![Setting::Isolated],
            trials: 4,
            ..CalibrationOptions::default()
        };
        let records = [
            record(Setting::Isolated, 4, true),
            record(Setting::Isolated, 3, false),
            record(Setting::Isolated, 1, false),
            record(Setting::Isolated, 0, false),
        ];
        let rows = tabulate(&opts, &records);
        let vs0 = &rows[0];
        assert_eq!(
            (
                vs0.counts.trials,
                vs0.counts.discarded,
                vs0.counts.successes
            ),
            (4, 2, 1)
        );
        assert_eq!(vs0.counts.rate, 0.5);
        assert_eq!(vs0.counts.se, binomial_se(1, 2));
        assert_eq!(vs0.by_setting[0].counts.discarded, 2);
        assert_eq!(vs0.by_setting[0].counts.rate, 0.5);
        // The consistency test sees the 2 counted attempts (1 success)
        // against the published 0 of 10: of the 12 attempts' single
        // success, the simulated 2 hold it with probability 2/12, and the
        // other table (0 of 2) is likelier, so p = 2/12.
        let p = vs0.by_setting[0].p_value.unwrap();
        assert!((p - 2.0 / 12.0).abs() < 1e-12, "{p}");
        assert_eq!(vs0.p_value, vs0.by_setting[0].p_value);
    }

    #[test]
    fn runs_over_seeds_pool_their_counts_and_summarise_their_errors() {
        let opts = CalibrationOptions {
            foods: vec![FoodKind::Carrot],
            settings: vec![Setting::Isolated, Setting::Lettuce],
            trials: 2,
            ..CalibrationOptions::default()
        };
        let mut logged = 0;
        let over =
            calibrate_over_seeds(&opts, &[3, 4], &|_, _, _| {}, &mut |_| logged += 1).unwrap();
        assert_eq!(logged, 2 * 6 * 2);
        let single: Vec<CalibrationReport> = [3, 4]
            .iter()
            .map(|&seed| {
                calibrate_with(
                    &CalibrationOptions {
                        seed,
                        ..opts.clone()
                    },
                    &|_, _| {},
                    &mut |_| {},
                )
                .unwrap()
            })
            .collect();
        // Each run is the run of its seed alone (timings aside).
        for (run, alone) in over.runs.iter().zip(&single) {
            assert_eq!(run.rows, alone.rows);
            assert_eq!(run.mean_abs_error, alone.mean_abs_error);
        }
        assert_eq!(over.seeds, vec![3, 4]);
        let means: Vec<f64> = single.iter().map(|r| r.mean_abs_error).collect();
        assert_eq!(over.mean_abs_error, Stat::of(&means));
        assert_eq!(
            over.runs_meeting_target,
            single.iter().filter(|r| r.meets_target).count()
        );
        // Pooled counts are the sums; rates and p-values follow from them.
        for (i, row) in over.pooled.iter().enumerate() {
            let (a, b) = (&single[0].rows[i], &single[1].rows[i]);
            assert_eq!(
                row.counts.successes,
                a.counts.successes + b.counts.successes
            );
            assert_eq!(row.counts.trials, 4);
            let t = Tally::of(
                row.counts.trials,
                row.counts.discarded,
                row.counts.successes,
            );
            assert_eq!(row.counts, t);
            let published = [
                FoodKind::Carrot.published_rates_in(Setting::Isolated)[i],
                FoodKind::Carrot.published_rates_in(Setting::Lettuce)[i],
            ];
            assert_eq!(row.p_value, consistency_p(&t, &published));
            for (j, cell) in row.by_setting.iter().enumerate() {
                assert_eq!(
                    cell.counts.successes,
                    a.by_setting[j].counts.successes + b.by_setting[j].counts.successes
                );
            }
        }
        assert_eq!(over.pooled_consistency.cells, 6);
        let err = calibrate_over_seeds(&opts, &[], &|_, _, _| {}, &mut |_| {}).unwrap_err();
        assert!(matches!(err, HilError::InvalidParameter { .. }), "{err:?}");
    }

    #[test]
    fn consistency_names_the_least_consistent_cell_and_adjusts_for_the_count() {
        let c = Consistency::over([
            ("carrot VS0".to_string(), Some(0.4)),
            ("carrot VS90".to_string(), Some(0.01)),
            ("carrot TV0".to_string(), None),
            ("banana TA0".to_string(), Some(0.04)),
        ]);
        assert_eq!(c.cells, 3);
        assert_eq!(c.below_0_05, 2);
        assert_eq!(c.least_consistent, "carrot VS90");
        let named: Vec<(&str, f64)> = c
            .cells_below_0_05
            .iter()
            .map(|x| (x.cell.as_str(), x.p))
            .collect();
        assert_eq!(named, [("carrot VS90", 0.01), ("banana TA0", 0.04)]);
        assert_eq!(c.smallest_p, 0.01);
        assert!((c.smallest_p_adjusted - 0.03).abs() < 1e-12);
        // Two or more of three cells below 0.05 by chance: 3·0.05²·0.95 + 0.05³.
        let two_of_three = 3.0 * 0.05f64.powi(2) * 0.95 + 0.05f64.powi(3);
        assert!((c.p_this_many_below_0_05 - two_of_three).abs() < 1e-12);
        // Bonferroni is capped at 1; no tested cell leaves p = 1.
        let many = Consistency::over((0..30).map(|i| (i.to_string(), Some(0.5))));
        assert_eq!(many.smallest_p_adjusted, 1.0);
        let none = Consistency::over([("x".to_string(), None)]);
        assert_eq!((none.cells, none.smallest_p), (0, 1.0));
        assert!((none.p_this_many_below_0_05 - 1.0).abs() < 1e-12);
    }
}
