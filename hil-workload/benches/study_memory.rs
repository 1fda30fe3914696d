//! Peak memory and time of loading and summarising a study CSV with one
//! long condition (what `hil workload summary` does), for 20,000 and
//! 200,000 query rows: both must grow linearly in the rows.
//!
//! Each size runs in a fresh child process (this executable, re-run with
//! `HIL_STUDY_BENCH_FILE` set) so that its peak resident set (`VmHWM` in
//! `/proc/self/status`, Linux) is its own. The parent writes the CSV under
//! `target/`, so the file's text is not part of the parent's measurement
//! either. Run with `cargo bench -p hil-workload --bench study_memory`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use hil_workload::bundle::StudySummary;
use hil_workload::study::Study;

mod common;

const CHILD_ENV: &str = "HIL_STUDY_BENCH_FILE";

/// One participant with one condition of `n` queries.
fn write_study(path: &Path, n: usize) {
    let text = common::long_condition_csv(&[("p1", "no_limitation")], n);
    std::fs::write(path, text).expect("writing the benchmark study");
}

/// Peak resident set of this process in kB (Linux), if known.
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn child(path: &Path) {
    let before = peak_rss_kb();
    let t0 = Instant::now();
    let study = Study::load(path).expect("the benchmark study is valid");
    let summary = StudySummary::of(&study).expect("the benchmark study summarises");
    let secs = t0.elapsed().as_secs_f64();
    let pairs: usize = summary.datasets.iter().map(|d| d.1).sum();
    println!(
        "{} {} {} {}",
        pairs,
        secs,
        before.unwrap_or(0),
        peak_rss_kb().unwrap_or(0)
    );
}

fn main() {
    if let Some(path) = std::env::var_os(CHILD_ENV) {
        child(Path::new(&path));
        return;
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../target/bench-study")
        .join(std::process::id().to_string());
    std::fs::create_dir_all(&dir).expect("creating the benchmark directory");
    let exe = std::env::current_exe().expect("the benchmark's own path");
    println!("study_memory: load + summarise a study with one condition of n queries");
    println!(
        "{:>8} {:>10} {:>12} {:>10} {:>14} {:>14}",
        "n", "file MB", "pairs (all)", "time s", "start RSS MB", "peak RSS MB"
    );
    for n in [20_000usize, 200_000] {
        let path = dir.join(format!("study_{n}.csv"));
        write_study(&path, n);
        let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        let out = std::process::Command::new(&exe)
            .env(CHILD_ENV, &path)
            .output()
            .expect("running the benchmark child");
        assert!(
            out.status.success(),
            "child failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout);
        let f: Vec<&str> = text.split_whitespace().collect();
        let kb = |s: &str| s.parse::<f64>().unwrap_or(0.0) / 1024.0;
        println!(
            "{:>8} {:>10.2} {:>12} {:>10.3} {:>14.1} {:>14.1}",
            n,
            size as f64 / 1e6,
            f[0],
            f[1].parse::<f64>().unwrap_or(f64::NAN),
            kb(f[2]),
            kb(f[3])
        );
        let _ = std::fs::remove_file(&path);
    }
    let _ = std::fs::remove_dir(&dir);
}
