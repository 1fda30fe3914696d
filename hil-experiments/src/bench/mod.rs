//! Benchmarks of hil's own components, as `hil bench` runs them: a policy's
//! decide + observe at scale against the memory-bandwidth floor
//! ([`policy`]), and the wall time of the full default reproduction
//! ([`reproduce`]). Each returns a report with its JSON form and a
//! one-line summary, so that the command only reads arguments and prints.

pub mod policy;
pub mod reproduce;
pub mod spec;

pub use policy::{PolicyBench, PolicyBenchReport};
pub use reproduce::{ReproduceBenchReport, bench_reproduce};
pub use spec::PolicySpec;

/// The 1-minute load average (`/proc/loadavg`, Linux; empty elsewhere):
/// reported beside every timing, since the machine may be shared.
pub fn load_average_1m() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_default()
}
