//! `hil bench reproduce`: wall time of the README's main job
//! ([`hil_experiments::bench::bench_reproduce`]).

use hil_core::{HilError, Result};

use crate::out::outln;

/// Arguments of `hil bench reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Timed runs (the first is also timed: nothing is cached across runs).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    #[command(flatten)]
    threads: crate::cmd::Threads,
}

pub fn run(a: ReproduceArgs) -> Result<()> {
    let report = hil_experiments::bench::bench_reproduce(a.runs, &a.threads.runner()?)?;
    outln!(
        "{}",
        serde_json::to_string_pretty(&report.to_json()).map_err(|e| HilError::serde("bench", e))?
    )
}
