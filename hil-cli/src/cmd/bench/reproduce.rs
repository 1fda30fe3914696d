//! `hil bench reproduce`: wall time of the README's main job, the full
//! default `hil reproduce` (the paper's 3-seed protocol and the many-seed
//! run beside it, selection, aggregation and the frontier), in process.

use std::time::Instant;

use hil_core::{HilError, Result};
use hil_experiments::{Protocol, ProtocolSettings};
use hil_stats::quantile;
use serde_json::json;

/// Arguments of `hil bench reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceBench {
    /// Timed runs (the first is also timed: nothing is cached across runs).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    #[command(flatten)]
    threads: crate::cmd::Threads,
}

pub fn bench_reproduce(a: &ReproduceBench) -> Result<()> {
    hil_config::limits::check_count("--runs", a.runs, 100)?;
    let runner = a.threads.runner()?;
    let threads = runner.threads();
    let mut wall = Vec::with_capacity(a.runs);
    let mut episodes = 0;
    for _ in 0..a.runs {
        let t0 = Instant::now();
        let protocol =
            Protocol::from_settings(ProtocolSettings::paper())?.with_runner(runner.clone());
        let records = protocol.run_all(&|_, _| {})?;
        protocol.reproduction(&records)?;
        wall.push(t0.elapsed().as_secs_f64());
        episodes = records.len();
    }
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_default();
    let out = json!({
        "job": "hil reproduce (default: 3-seed protocol + 30-seed run, 6 workload models)",
        "episodes": episodes,
        "threads": threads,
        "runs": a.runs,
        "wall_s": wall,
        "wall_s_min": quantile(&wall, 0.0),
        // The upper of the two middle runs for an even count.
        "wall_s_median": quantile(&wall, 0.5),
        "loadavg_1min_at_end": load,
    });
    println!(
        "{}",
        serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("bench", e))?
    );
    Ok(())
}
