//! Cost of simulated skewering attempts with the published 5 s hold.
//!
//! One iteration runs one attempt per (food, action, setting): 3 foods × 6
//! actions × 3 settings = 54 attempts on one thread, exactly as
//! `hil kinova calibrate --trials 3 --threads 1` does. Criterion reports
//! the wall time of an iteration; after it, the bench prints what bounds
//! it from the simulator's own accounting: attempts per second of thread
//! CPU time (per core), physics steps per attempt, µs of CPU per
//! `mj_step`, and the share of time spent outside `mj_step`.
//!
//! `cargo bench -p hil-kinova-mujoco --bench attempt`

use criterion::{Criterion, criterion_group, criterion_main};
use hil_kinova_mujoco::{CalibrationOptions, CalibrationReport, calibrate_with};

fn opts() -> CalibrationOptions {
    CalibrationOptions {
        trials: 3,
        threads: 1,
        ..CalibrationOptions::default()
    }
}

fn run() -> CalibrationReport {
    calibrate_with(&opts(), &|_, _| {}, &mut |_| {}).expect("calibration attempts run")
}

fn attempts(c: &mut Criterion) {
    let mut g = c.benchmark_group("kinova");
    g.sample_size(10);
    g.bench_function("54_attempts_5s_hold", |b| b.iter(run));
    g.finish();
    let r = run();
    println!(
        "speed (one thread, {:.0} s hold): {:.1} attempts/s per core, {:.0} steps/attempt, \
         {:.1} µs/step, {:.1} % outside mj_step",
        r.hold_s,
        r.attempts_per_second_per_core,
        r.steps_per_attempt,
        r.micros_per_step,
        100.0 * r.overhead_share
    );
}

criterion_group!(benches, attempts);
criterion_main!(benches);
