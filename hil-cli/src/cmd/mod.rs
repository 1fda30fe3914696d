//! One module per subcommand.

pub mod bench;
pub mod data;
#[cfg(feature = "physics")]
pub mod kinova;
// Without MuJoCo, `hil kinova` and `hil demo` only say how to enable them.
#[cfg(not(feature = "physics"))]
#[path = "without_physics.rs"]
pub mod kinova;
pub mod plugins;
pub mod reproduce;
pub mod run;
pub mod study;
pub mod workload;

/// A rayon pool of `threads` workers (default: all cores) and its size.
pub fn worker_pool(threads: Option<usize>) -> hil_core::Result<(rayon::ThreadPool, usize)> {
    let threads = threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| hil_core::HilError::state("thread pool", e.to_string()))?;
    Ok((pool, threads))
}
