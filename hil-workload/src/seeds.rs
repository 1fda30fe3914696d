//! The synthetic study over many generator seeds.
//!
//! One generated study is one draw: its D1 and D2 means scatter around
//! what the generator gives in expectation. The generator is calibrated so
//! that the *expectation* (the mean over seeds) matches the paper's
//! published figures; [`SeedSpread`] measures it, with the spread over
//! seeds, and [`centre`] is the calibration itself.
//!
//! ```no_run
//! use hil_workload::seeds::SeedSpread;
//! use hil_workload::synth::SynthConfig;
//! let s = SeedSpread::over(&SynthConfig::default(), 0..100).unwrap();
//! println!("{}", s.to_text());
//! ```

use std::ops::Range;

use hil_core::Result;
use hil_paper::workload_study::{D1_BELOW_D2_P, D1_WORKLOAD, D2_WORKLOAD};
use hil_stats::Stat;
use serde::{Deserialize, Serialize};

use crate::bundle::StudySummary;
use crate::datasets::DatasetId;
use crate::synth::SynthConfig;

/// One generated study's headline figures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Draw {
    /// Generator seed.
    pub seed: u64,
    /// D1 pairs, mean WL, sd WL.
    pub d1: (usize, f64, f64),
    /// D2 pairs, mean WL, sd WL.
    pub d2: (usize, f64, f64),
    /// One-sided Mann-Whitney p, D1 < D2.
    pub p: f64,
}

impl Draw {
    /// The figures of the study generated from `seed` (its
    /// [`StudySummary`], the one `hil workload summary` prints).
    pub fn of(config: &SynthConfig, seed: u64) -> Result<Self> {
        let study = config.generate(seed)?;
        let summary = StudySummary::of(&study)?;
        let figures = |id: DatasetId| {
            summary
                .datasets
                .iter()
                .find(|d| d.0 == id)
                .map(|&(_, n, m, sd, _)| (n, m, sd))
                .ok_or_else(|| crate::datasets::no_query_rows(&study, id))
        };
        Ok(Self {
            seed,
            d1: figures(DatasetId::D1)?,
            d2: figures(DatasetId::D2)?,
            // Present whenever D1 and D2 are.
            p: summary
                .d1_less_than_d2
                .map(|t| t.p_value)
                .ok_or_else(|| crate::datasets::no_query_rows(&study, DatasetId::D2))?,
        })
    }
}

/// The generator's figures over a range of seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeedSpread {
    /// Every draw.
    pub draws: Vec<Draw>,
    /// D1 mean WL over seeds (`std`: how far one draw falls; `se`: how
    /// well the seeds pin the generator's expectation).
    pub d1_mean: Stat,
    /// D1 sd WL over seeds.
    pub d1_sd: Stat,
    /// D2 mean WL over seeds.
    pub d2_mean: Stat,
    /// D2 sd WL over seeds.
    pub d2_sd: Stat,
    /// Median p over seeds.
    pub p_median: f64,
    /// Share of seeds with p < 0.05.
    pub p_below_005: f64,
}

impl SeedSpread {
    /// Generates one study per seed in `seeds` (in parallel on the default
    /// [`hil_jobs::Runner`]); `seeds` holds 1 to
    /// [`hil_config::limits::SEEDS`] of them.
    pub fn over(config: &SynthConfig, seeds: Range<u64>) -> Result<Self> {
        // Checked before the list is built (`hil_config::limits::SEEDS`).
        let n = seeds.end.saturating_sub(seeds.start);
        hil_config::limits::check_count("seeds", n, hil_config::limits::SEEDS)?;
        let seeds: Vec<u64> = seeds.collect();
        let draws: Vec<Draw> = hil_jobs::Runner::default().map(&seeds, |&s| Draw::of(config, s))?;
        let col = |f: &dyn Fn(&Draw) -> f64| Stat::of(&draws.iter().map(f).collect::<Vec<_>>());
        let ps: Vec<f64> = draws.iter().map(|d| d.p).collect();
        let p_median = hil_stats::median(&ps);
        let p_below_005 = ps.iter().filter(|p| **p < 0.05).count() as f64 / ps.len().max(1) as f64;
        Ok(Self {
            d1_mean: col(&|d| d.d1.1),
            d1_sd: col(&|d| d.d1.2),
            d2_mean: col(&|d| d.d2.1),
            d2_sd: col(&|d| d.d2.2),
            p_median,
            p_below_005,
            draws,
        })
    }

    /// A table beside the paper's figures.
    pub fn to_text(&self) -> String {
        let row = |name: &str, o: &Stat, paper: f64| {
            format!(
                "{name:<8} {:.3} (SE {:.3}; one draw ± {:.3})   paper {paper}\n",
                o.mean, o.se, o.std
            )
        };
        let mut s = format!(
            "over {} generator seeds (mean over seeds, its standard error, and the sd of one draw):\n",
            self.draws.len()
        );
        s.push_str(&row("D1 mean", &self.d1_mean, D1_WORKLOAD.mean));
        s.push_str(&row("D1 sd", &self.d1_sd, D1_WORKLOAD.sd));
        s.push_str(&row("D2 mean", &self.d2_mean, D2_WORKLOAD.mean));
        s.push_str(&row("D2 sd", &self.d2_sd, D2_WORKLOAD.sd));
        s.push_str(&format!(
            "Mann-Whitney p (D1 < D2): median {:.2e}, below 0.05 in {:.0} % of seeds   paper {:e}\n",
            self.p_median,
            100.0 * self.p_below_005,
            D1_BELOW_D2_P
        ));
        if let Some(d) = self.draws.first() {
            s.push_str(&format!("pairs per draw: D1 {}, D2 {}\n", d.d1.0, d.d2.0));
        }
        s
    }
}

/// The calibration of the generator's level and spread parameters:
/// starting from `config`, adjusts `params.mean` (the D1 level),
/// `params.population_shift` (D2's extra level), `params.participant_sd` (the spread
/// of participants' levels, which a model partly sees through WL_0) and `params.limited_survey_sd` (D2's) until the mean
/// over `seeds` of the D1 and D2 means and sds is within `tolerance` of
/// the paper's. A fixed-point iteration on the gaps (levels move with the
/// gap, variances with the gap in variance); clamping and Likert rounding
/// make the response nonlinear, so a few rounds are needed. Returns the
/// calibrated config and its spread.
pub fn centre(
    config: &SynthConfig,
    seeds: Range<u64>,
    tolerance: f64,
    max_rounds: usize,
) -> Result<(SynthConfig, SeedSpread)> {
    let mut c = config.clone();
    let mut spread = SeedSpread::over(&c, seeds.clone())?;
    let round = |x: f64| (x * 1e4).round() / 1e4;
    for _ in 0..max_rounds {
        let g1 = D1_WORKLOAD.mean - spread.d1_mean.mean;
        let g2 = D2_WORKLOAD.mean - spread.d2_mean.mean;
        let v1 = D1_WORKLOAD.sd.powi(2) - spread.d1_sd.mean.powi(2);
        let v2 = D2_WORKLOAD.sd.powi(2) - spread.d2_sd.mean.powi(2);
        if [
            g1,
            g2,
            D1_WORKLOAD.sd - spread.d1_sd.mean,
            D2_WORKLOAD.sd - spread.d2_sd.mean,
        ]
        .iter()
        .all(|g| g.abs() <= tolerance)
        {
            break;
        }
        let p = &mut c.params;
        // D1 moves with `mean`; D2 with `mean + population_shift`.
        p.mean = round(p.mean + g1);
        p.population_shift = round(p.population_shift + g2 - g1);
        // Independent noise: variances add.
        p.participant_sd = round((p.participant_sd.powi(2) + v1).max(0.0).sqrt());
        p.limited_survey_sd = round((p.limited_survey_sd.powi(2) + v2).max(0.0).sqrt());
        spread = SeedSpread::over(&c, seeds.clone())?;
    }
    Ok((c, spread))
}
