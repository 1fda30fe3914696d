//! # hil-jobs
//!
//! The one job runner of hil: every parallel loop in the workspace (the
//! testbed's episodes, the user study over seeds, model selection's folds,
//! the Kinova calibration's attempts, synthetic studies over seeds) runs
//! through [`Runner`], so a thread count means the same thing everywhere:
//!
//! - `threads = 0`: rayon's default pool, i.e. `RAYON_NUM_THREADS` when
//!   set, else one worker per core (and, inside an `install`ed pool, that
//!   pool);
//! - `threads = n > 0`: a pool of its own with exactly `n` workers.
//!
//! [`Runner::map`] returns results in input order whatever the thread count,
//! so a parallel run gives what a serial one gives; the first failing job's
//! error stops the run. A leaf crate (rayon and hil-core's error type only),
//! so that the workload and physics crates can use it as well as the
//! protocols.
//!
//! ```
//! let runner = hil_jobs::Runner::new(2).unwrap();
//! let squares: Result<Vec<u64>, String> = runner.map(&[1u64, 2, 3], |&x| Ok(x * x));
//! assert_eq!(squares.unwrap(), [1, 4, 9]);
//! ```

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use hil_core::{HilError, Result};
use rayon::prelude::*;

/// Runs jobs in parallel on a fixed number of worker threads, results in
/// input order. Cheap to clone (clones share the pool).
#[derive(Clone, Debug)]
pub struct Runner {
    /// `None`: rayon's current pool (`threads = 0`).
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Default for Runner {
    /// rayon's default pool (`threads = 0`).
    fn default() -> Self {
        Self { pool: None }
    }
}

/// The stack of a runner's worker thread: a main thread's (8 MiB), not
/// rayon's default 2 MiB, because jobs run components written elsewhere
/// (Python ones, with NumPy, whose threaded OpenBLAS keeps per-thread tables
/// on the calling thread's stack and overflows 2 MiB).
pub const WORKER_STACK_BYTES: usize = 8 << 20;

/// Most worker threads a runner starts: a `--threads` typo of many digits
/// is an error naming `threads`, not thousands of threads spawned until
/// the system refuses one.
pub const MAX_THREADS: usize = 1024;

impl Runner {
    /// A runner on `threads` workers (at most [`MAX_THREADS`]); 0 means
    /// rayon's default pool (`RAYON_NUM_THREADS`, else one worker per core).
    ///
    /// ```
    /// use hil_jobs::Runner;
    /// use hil_core::HilError;
    /// assert_eq!(Runner::new(3).unwrap().threads(), 3);
    /// assert!(Runner::new(0).unwrap().threads() >= 1);
    /// let err = Runner::new(100_000).unwrap_err();
    /// assert!(matches!(err, HilError::InvalidParameter { ref name, .. } if name == "threads"));
    /// ```
    pub fn new(threads: usize) -> Result<Self> {
        if threads == 0 {
            return Ok(Self::default());
        }
        if threads > MAX_THREADS {
            return Err(HilError::invalid_parameter(
                "threads",
                threads,
                format!("must be between 0 (one per core) and {MAX_THREADS}"),
            ));
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .stack_size(WORKER_STACK_BYTES)
            .build()
            .map_err(|e| HilError::state("thread pool", e.to_string()))?;
        Ok(Self {
            pool: Some(Arc::new(pool)),
        })
    }

    /// The number of worker threads jobs run on.
    pub fn threads(&self) -> usize {
        match &self.pool {
            Some(pool) => pool.current_num_threads(),
            None => rayon::current_num_threads(),
        }
    }

    /// Runs `op` on this runner's pool: rayon parallel iterators inside it
    /// use this runner's workers.
    fn install<R: Send>(&self, op: impl FnOnce() -> R + Send) -> R {
        match &self.pool {
            Some(pool) => pool.install(op),
            None => op(),
        }
    }

    /// `job` applied to every item in parallel; the results in the order of
    /// `items`. The first error (in the order the workers meet them) stops
    /// the run: no further jobs are started, and it is returned.
    pub fn map<T, R, E>(
        &self,
        items: &[T],
        job: impl Fn(&T) -> std::result::Result<R, E> + Sync,
    ) -> std::result::Result<Vec<R>, E>
    where
        T: Sync,
        R: Send,
        E: Send,
    {
        self.map_with_progress(items, job, &|_, _| {})
    }

    /// [`Runner::map`] calling `progress(done, total)` after every job, from
    /// the worker that ran it.
    ///
    /// ```
    /// use std::sync::atomic::{AtomicUsize, Ordering};
    /// let seen = AtomicUsize::new(0);
    /// let out: Result<Vec<usize>, ()> = hil_jobs::Runner::new(2).unwrap().map_with_progress(
    ///     &[10, 20, 30],
    ///     |&x| Ok(x + 1),
    ///     &|done, total| {
    ///         assert!(done <= total);
    ///         seen.fetch_add(1, Ordering::Relaxed);
    ///     },
    /// );
    /// assert_eq!(out.unwrap(), [11, 21, 31]);
    /// assert_eq!(seen.into_inner(), 3);
    /// ```
    pub fn map_with_progress<T, R, E>(
        &self,
        items: &[T],
        job: impl Fn(&T) -> std::result::Result<R, E> + Sync,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> std::result::Result<Vec<R>, E>
    where
        T: Sync,
        R: Send,
        E: Send,
    {
        let total = items.len();
        let done = AtomicUsize::new(0);
        self.install(|| {
            items
                .par_iter()
                .map(|item| {
                    let r = job(item);
                    progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    r
                })
                .collect()
        })
    }

    /// [`Runner::map_with_progress`] where every worker thread keeps a state
    /// of its own across the jobs it runs (e.g. a simulator that costs far
    /// more to build than a job): `job` gets the state of the worker running
    /// it, made by `init` on that worker's first job. Returns the results in
    /// input order and every state made (in no particular order), so that a
    /// caller can read what the states gathered (e.g. timings).
    ///
    /// The results must not depend on which worker ran a job: a state is a
    /// cache, never an input.
    ///
    /// ```
    /// let runner = hil_jobs::Runner::new(2).unwrap();
    /// let (out, states) = runner
    ///     .map_per_worker(&[1, 2, 3, 4], Vec::new, |seen: &mut Vec<i32>, &x| {
    ///         seen.push(x);
    ///         Ok::<_, ()>(x * 10)
    ///     }, &|_, _| {})
    ///     .unwrap();
    /// assert_eq!(out, [10, 20, 30, 40]);
    /// assert_eq!(states.iter().map(Vec::len).sum::<usize>(), 4);
    /// ```
    pub fn map_per_worker<T, R, E, S>(
        &self,
        items: &[T],
        init: impl Fn() -> S + Sync,
        job: impl Fn(&mut S, &T) -> std::result::Result<R, E> + Sync,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> std::result::Result<(Vec<R>, Vec<S>), E>
    where
        T: Sync,
        R: Send,
        E: Send,
        S: Send,
    {
        let states: Vec<Mutex<Option<S>>> = (0..self.threads()).map(|_| Mutex::new(None)).collect();
        let results = self.map_with_progress(
            items,
            |item| {
                // A worker's index is unique within its pool, so no two
                // workers share a state (the lock is never contended).
                let worker = rayon::current_thread_index().unwrap_or(0) % states.len();
                let mut slot = lock(&states[worker]);
                let state = slot.get_or_insert_with(&init);
                job(state, item)
            },
            progress,
        )?;
        let states = states
            .into_iter()
            .filter_map(|s| s.into_inner().unwrap_or_else(PoisonError::into_inner))
            .collect();
        Ok((results, states))
    }
}

/// A worker's state, also after another worker panicked while holding its
/// own (the panic itself reaches the caller through rayon).
fn lock<S>(m: &Mutex<S>) -> MutexGuard<'_, S> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_keep_input_order_at_every_thread_count() {
        let items: Vec<u64> = (0..200).collect();
        let serial: Vec<u64> = items.iter().map(|x| x * 3 + 1).collect();
        for threads in [0, 1, 2, 5] {
            let out: std::result::Result<Vec<u64>, ()> =
                Runner::new(threads).unwrap().map(&items, |x| Ok(x * 3 + 1));
            assert_eq!(out.unwrap(), serial, "{threads} threads");
        }
    }

    #[test]
    fn an_error_stops_the_run_and_is_returned() {
        let started = AtomicUsize::new(0);
        let out = Runner::new(1)
            .unwrap()
            .map(&(0..100).collect::<Vec<_>>(), |&x| {
                started.fetch_add(1, Ordering::Relaxed);
                if x == 3 {
                    Err(format!("job {x}"))
                } else {
                    Ok(x)
                }
            });
        assert_eq!(out.unwrap_err(), "job 3");
        assert!(started.into_inner() < 100, "jobs after the error still ran");
    }

    #[test]
    fn threads_is_the_pool_size() {
        assert_eq!(Runner::new(1).unwrap().threads(), 1);
        assert_eq!(Runner::new(4).unwrap().threads(), 4);
        let inside = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap()
            .install(|| Runner::new(0).unwrap().threads());
        assert_eq!(inside, 3, "0 runs on the pool it is called in");
    }

    #[test]
    fn progress_counts_every_job_once() {
        let calls = Mutex::new(Vec::new());
        let _: Vec<usize> = Runner::new(3)
            .unwrap()
            .map_with_progress(&[1, 2, 3, 4, 5], |&x| Ok::<_, ()>(x), &|done, total| {
                lock(&calls).push((done, total))
            })
            .unwrap();
        let mut calls = calls.into_inner().unwrap();
        calls.sort();
        assert_eq!(calls, (1..=5).map(|d| (d, 5)).collect::<Vec<_>>());
    }

    #[test]
    fn a_worker_keeps_its_state_across_jobs() {
        let (out, states) = Runner::new(1)
            .unwrap()
            .map_per_worker(
                &[1, 2, 3],
                || 0,
                |n: &mut i32, &x| {
                    *n += 1;
                    Ok::<_, ()>(x + *n)
                },
                &|_, _| {},
            )
            .unwrap();
        // One worker: one state, built once, seeing every job in order.
        assert_eq!(states, [3]);
        assert_eq!(out, [2, 4, 6]);
    }
}
