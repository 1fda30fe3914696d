//! The cost curve of model selection and Exp-Impulse fitting in the rows of
//! a condition: `hil workload select` (every candidate of the paper's table,
//! nested 4×5-fold cross-validation, on D1, D2 and D12) and
//! `hil workload fit --model exp_impulse` on studies whose two participants
//! (one per population) each answer one long condition, on one thread.
//! Both must grow linearly in the rows (issue 31, item 28: `select` on a
//! 200,000-query study within 60 s).
//!
//! `cargo bench -p hil-workload --bench select_scaling` prints the
//! queries, the pairs (D1 + D2 + D12), `select`'s wall and CPU seconds, the
//! Exp-Impulse fit's wall seconds (D1) and the load average;
//! under `cargo test --benches` (no `--bench` flag) only the smallest size
//! runs, as a check that the bench works; `HIL_SELECT_SIZES=a,b,...` picks
//! the sizes. Synthetic data.

use std::time::Instant;

use hil_workload::datasets::{Dataset, DatasetId};
use hil_workload::select::{Candidate, SelectOptions, fit_on_all, select_study_models};
use hil_workload::study::Study;

mod common;

fn main() {
    let full = std::env::args().any(|a| a == "--bench");
    // HIL_SELECT_SIZES=10000,200000 picks the sizes.
    let sizes: Vec<usize> = match std::env::var("HIL_SELECT_SIZES") {
        Ok(list) => list
            .split(',')
            .map(|n| {
                n.trim()
                    .parse()
                    .expect("HIL_SELECT_SIZES: comma-separated counts")
            })
            .collect(),
        Err(_) if full => vec![2_500, 5_000, 10_000, 25_000, 50_000, 100_000, 200_000],
        Err(_) => vec![2_000],
    };
    let opts = SelectOptions {
        threads: 1,
        ..SelectOptions::default()
    };
    println!("select_scaling: one thread, synthetic long conditions");
    println!(
        "{:>9} {:>9} {:>10} {:>12} {:>10} {:>14} {:>6}",
        "queries", "pairs", "select s", "select cpu s", "fit s", "cpu µs/pair", "load"
    );
    for n in sizes {
        // Half the queries for each population, so D1 and D2 each hold one
        // condition of n/2 queries and D12 both.
        let text = common::long_condition_csv(
            &[("p1", "no_limitation"), ("p2", "mobility_limitation")],
            n / 2,
        );
        let study = Study::parse(&text, "synthetic long conditions".as_ref())
            .expect("the benchmark study is valid");
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let table = select_study_models(&study, &opts).expect("selection runs");
        let select_s = t0.elapsed().as_secs_f64();
        let select_cpu = cpu_seconds() - c0;
        let pairs: usize = table.n_pairs.iter().map(|(_, n)| n).sum();
        let d1 = Dataset::build(&study, DatasetId::D1).expect("D1 builds");
        let t1 = Instant::now();
        fit_on_all(&d1, Candidate::ExpImpulse, &opts).expect("Exp-Impulse fits");
        let fit_s = t1.elapsed().as_secs_f64();
        println!(
            "{:>9} {:>9} {:>10.2} {:>12.2} {:>10.2} {:>14.2} {:>6}",
            n,
            pairs,
            select_s,
            select_cpu,
            fit_s,
            select_cpu / pairs as f64 * 1e6,
            load_average_1m()
        );
    }
}

/// CPU time of this process so far (user + system, all threads), from
/// `/proc/self/stat` (Linux; NaN elsewhere): on a shared machine the wall
/// time also counts other processes' turns.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the parenthesised command name; utime and stime are
    // the 14th and 15th fields, in clock ticks (100 per second on Linux).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        f.get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The 1-minute load average (Linux; empty elsewhere).
fn load_average_1m() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_default()
}
