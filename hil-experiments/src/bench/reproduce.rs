//! Wall time of the README's main job, the full default `hil reproduce`
//! (the paper's 3-seed protocol and the many-seed run beside it, selection,
//! aggregation and the frontier), in process.

use std::time::Instant;

use hil_core::Result;
use hil_jobs::Runner;
use hil_stats::quantile;
use serde_json::json;

use crate::{Protocol, ProtocolSettings};

/// The timings of [`bench_reproduce`].
#[derive(Clone, Debug, PartialEq)]
pub struct ReproduceBenchReport {
    /// Episodes of one run.
    pub episodes: usize,
    /// Worker threads.
    pub threads: usize,
    /// Wall time of each run, in seconds.
    pub wall_s: Vec<f64>,
    /// The 1-minute load average at the end.
    pub load_average_1m: String,
}

impl ReproduceBenchReport {
    /// The report as `hil bench reproduce` prints it.
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "job": "hil reproduce (default: 3-seed protocol + 30-seed run, the calibrated workload models in three variants, the paper-implied and hil grids)",
            "episodes": self.episodes,
            "threads": self.threads,
            "runs": self.wall_s.len(),
            "wall_s": self.wall_s,
            "wall_s_min": quantile(&self.wall_s, 0.0),
            // The upper of the two middle runs for an even count.
            "wall_s_median": quantile(&self.wall_s, 0.5),
            "loadavg_1min_at_end": self.load_average_1m,
        })
    }
}

/// Runs the default reproduction `runs` times on `runner` (each run timed;
/// nothing is cached across runs).
pub fn bench_reproduce(runs: usize, runner: &Runner) -> Result<ReproduceBenchReport> {
    hil_config::limits::check_count("--runs", runs, 100)?;
    let mut wall_s = Vec::with_capacity(runs);
    let mut episodes = 0;
    for _ in 0..runs {
        let t0 = Instant::now();
        let protocol =
            Protocol::from_settings(ProtocolSettings::paper())?.with_runner(runner.clone());
        let records = protocol.run_all(&|_, _| {})?;
        protocol.reproduction(&records)?;
        wall_s.push(t0.elapsed().as_secs_f64());
        episodes = records.len();
    }
    Ok(ReproduceBenchReport {
        episodes,
        threads: runner.threads(),
        wall_s,
        load_average_1m: super::load_average_1m(),
    })
}
