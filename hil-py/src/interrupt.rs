//! Long Rust work that Ctrl-C can stop.
//!
//! CPython runs signal handlers only on the main thread and only when that
//! thread executes Python code, so a call that stays in Rust for minutes
//! would swallow Ctrl-C until it returns. [`run_interruptibly`] therefore
//! runs the work on a worker thread while the calling thread, with the GIL
//! released, waits for it and every [`POLL`] takes the GIL to run pending
//! signal handlers (`Python::check_signals`). When a handler raises (Ctrl-C
//! raises `KeyboardInterrupt`), the worker is asked to stop through its
//! [`StopFlag`] and the calling thread waits for it to finish, so nothing
//! keeps running behind the exception; a second Ctrl-C during that wait
//! returns at once and leaves the worker to finish on its own.
//!
//! The work checks the flag where stopping leaves things consistent:
//! [`StopAtBoundary`] does so for hil's session loop, between steps, so an
//! interaction log written so far is complete and `resume` continues it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use hil_core::{HilError, Item, SessionObserver, StepEvent};
use pyo3::prelude::*;

/// How often the waiting thread runs Python's signal handlers: short
/// enough that Ctrl-C feels immediate, long enough to cost nothing.
pub(crate) const POLL: Duration = Duration::from_millis(20);

/// Set when the caller was interrupted; the work should stop at its next
/// safe point.
#[derive(Clone, Debug, Default)]
pub(crate) struct StopFlag(Arc<AtomicBool>);

impl StopFlag {
    /// Whether a stop was asked for.
    pub(crate) fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// An error when a stop was asked for (the caller raises the Python
    /// exception that asked; this error only ends the work).
    pub(crate) fn check(&self) -> hil_core::Result<()> {
        if self.is_set() {
            Err(HilError::state("session", "interrupted from Python"))
        } else {
            Ok(())
        }
    }
}

/// Runs `work` on a worker thread, returning its result, or the exception
/// a signal handler raised meanwhile (after asking the work to stop; see the
/// module doc). The GIL is released while waiting, so Python components the
/// work calls can take it.
pub(crate) fn run_interruptibly<T, F>(py: Python<'_>, name: &str, work: F) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce(StopFlag) -> T + Send + 'static,
{
    let stop = StopFlag::default();
    let (done, mut result) = channel();
    let worker_stop = stop.clone();
    std::thread::Builder::new()
        .name(format!("hil-{name}"))
        .spawn(move || {
            // The receiver is gone only if the caller gave up waiting.
            let _ = done.send(work(worker_stop));
        })
        .map_err(|e| {
            crate::errors::to_py_err(HilError::state(
                name,
                format!("cannot start its thread: {e}"),
            ))
        })?;
    let mut interrupted: Option<PyErr> = None;
    loop {
        // The receiver moves in and out: it may not be shared across threads.
        let (received, back) = py.detach(move || (result.recv_timeout(POLL), result));
        result = back;
        match received {
            Ok(value) => {
                return match interrupted {
                    Some(e) => Err(e),
                    None => Ok(value),
                };
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(crate::errors::to_py_err(HilError::state(
                    name,
                    "its thread panicked",
                )));
            }
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    if interrupted.is_some() {
                        // Asked twice: stop waiting for the current step.
                        return Err(e);
                    }
                    stop.set();
                    interrupted = Some(e);
                }
            }
        }
    }
}

/// A session observer that ends the session at the next boundary between
/// steps once `flag` is set: after a step's outcome is recorded, or before
/// an item or episode starts (never between a recorded step and its
/// outcome). Put it after the recorder, which has then written the step.
pub(crate) struct StopAtBoundary(pub(crate) StopFlag);

impl SessionObserver for StopAtBoundary {
    fn on_episode_start(&mut self, _: u64) -> hil_core::Result<()> {
        self.0.check()
    }
    fn on_item_start(&mut self, _: &Item) -> hil_core::Result<()> {
        self.0.check()
    }
    fn on_step(&mut self, _: &StepEvent) -> hil_core::Result<()> {
        self.0.check()
    }
}
