//! Success rates per (food, action) over randomised trials, beside the
//! published rates (Feng et al. 2019, setting `all`).
//!
//! ```
//! use hil_kinova_mujoco::calibrate::calibrate_foods;
//! use hil_kinova_mujoco::FoodKind;
//!
//! // `calibrate(30, 1)` runs every food; one trial on carrot here.
//! let report = calibrate_foods(&[FoodKind::Carrot], 1, 1, &mut |_, _| {})?;
//! assert_eq!(report.rows.len(), 6);
//! assert_eq!(report.rows[1].published, Some(0.53)); // VS90
//! # Ok::<(), hil_core::HilError>(())
//! ```

use std::time::Instant;

use hil_core::{ArmId, Environment, Result};
use serde::Serialize;

use crate::controller::ACTIONS;
use crate::env::{KinovaFeedingConfig, KinovaFeedingEnv};
use crate::food::FoodKind;

/// One (food, action) cell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationRow {
    /// Food.
    pub food: String,
    /// Action label.
    pub action: String,
    /// Trials run.
    pub trials: usize,
    /// Successes.
    pub successes: usize,
    /// Achieved success rate.
    pub rate: f64,
    /// Published rate, where one exists.
    pub published: Option<f64>,
}

/// The calibration table and throughput.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationReport {
    /// One row per (food, action).
    pub rows: Vec<CalibrationRow>,
    /// Mean absolute difference to the published rates.
    pub mean_abs_error: f64,
    /// Simulated attempts per wall-clock second (one core).
    pub attempts_per_second: f64,
    /// Share of wall-clock time spent outside `mj_step`.
    pub overhead_share: f64,
    /// Provenance note.
    pub note: &'static str,
}

/// Runs `trials` randomised attempts of every action on every food.
pub fn calibrate(trials: usize, seed: u64) -> Result<CalibrationReport> {
    calibrate_foods(&FoodKind::ALL, trials, seed, &mut |_, _| {})
}

/// Like [`calibrate`] for some foods, reporting progress `(done, total)`.
pub fn calibrate_foods(
    foods: &[FoodKind],
    trials: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<CalibrationReport> {
    let start = Instant::now();
    let mut rows = Vec::new();
    let total = foods.len() * ACTIONS.len() * trials;
    let mut done = 0;
    let mut in_step = std::time::Duration::ZERO;
    let mut sim_total = std::time::Duration::ZERO;
    for &food in foods {
        let cfg = KinovaFeedingConfig {
            plate: vec![food.name().to_string(); 1],
            ..KinovaFeedingConfig::default()
        };
        let mut env = KinovaFeedingEnv::new(cfg)?;
        for (a, action) in ACTIONS.iter().enumerate() {
            let mut successes = 0;
            for t in 0..trials {
                env.reset(
                    seed.wrapping_mul(1_000_003)
                        .wrapping_add((food.index() * 6 + a) as u64 * 10_007 + t as u64),
                )?;
                env.next_item()?;
                env.observe()?;
                if env.execute(ArmId(a))?.success {
                    successes += 1;
                }
                done += 1;
                progress(done, total);
            }
            rows.push(CalibrationRow {
                food: food.name().into(),
                action: action.name.into(),
                trials,
                successes,
                rate: successes as f64 / trials.max(1) as f64,
                published: Some(food.published_rates()[a]),
            });
        }
        let t = env.simulator().timing();
        in_step += t.in_step;
        sim_total += t.total;
    }
    let errs: Vec<f64> = rows
        .iter()
        .filter_map(|r| r.published.map(|p| (p - r.rate).abs()))
        .collect();
    let wall = start.elapsed().as_secs_f64();
    Ok(CalibrationReport {
        mean_abs_error: errs.iter().sum::<f64>() / errs.len().max(1) as f64,
        attempts_per_second: total as f64 / wall.max(1e-9),
        overhead_share: 1.0 - in_step.as_secs_f64() / sim_total.as_secs_f64().max(1e-9),
        rows,
        note: "simulated (MuJoCo) attempts with synthetic food properties; published rates: Feng et al. 2019, setting `all`",
    })
}
