//! Long Rust work that Ctrl-C stops and that reports progress.
//!
//! CPython runs signal handlers only on the main thread and only when that
//! thread executes Python code, so a call that stays in Rust for minutes
//! would swallow Ctrl-C until it returns. [`run`] therefore runs the work
//! on a scoped thread with the GIL released, while the calling thread wakes
//! every [`POLL`] to report progress and to let Python run its signal
//! handlers. A `KeyboardInterrupt` (or any exception the progress callback
//! raises) raises the work's cancel flag, waits for the work to stop, and
//! is then raised to the caller, so nothing keeps running behind the
//! exception.
//!
//! The work checks the flag where stopping leaves things consistent:
//! `Protocol::run_until_cancelled` between runs (`hil.reproduce`, the
//! in-process `hil.sweep`), and [`StopAtBoundary`] between the steps of
//! hil's session loop (`hil.run`, `hil.run_session`), so an interaction log
//! written so far is complete and `resume` continues it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use hil_core::{HilError, Item, SessionObserver, StepEvent};
use pyo3::prelude::*;

/// How often the caller's thread wakes to check signals and report.
const POLL: Duration = Duration::from_millis(50);

/// What the work and the polling thread share.
#[derive(Debug, Default)]
pub(crate) struct Control {
    /// Raised when the caller wants the work to stop.
    pub(crate) cancel: AtomicBool,
    done: AtomicUsize,
    total: AtomicUsize,
}

impl Control {
    /// Records that `done` of `total` units are finished.
    pub(crate) fn report(&self, done: usize, total: usize) {
        self.total.store(total, Ordering::Relaxed);
        self.done.fetch_max(done, Ordering::Relaxed);
    }

    /// Whether the caller asked the work to stop.
    pub(crate) fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    fn progress(&self) -> (usize, usize) {
        (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }
}

/// Where progress goes: a callable `progress(done, total)`, or `True` for a
/// line on `sys.stderr` (rewritten in place).
enum Sink<'py> {
    Call(Bound<'py, PyAny>),
    Stderr(&'static str),
}

impl Sink<'_> {
    fn of<'py>(progress: Option<&Bound<'py, PyAny>>, what: &'static str) -> Option<Sink<'py>> {
        let p = progress?;
        if p.is_none() {
            return None;
        }
        if p.is_callable() {
            return Some(Sink::Call(p.clone()));
        }
        p.is_truthy().ok()?.then_some(Sink::Stderr(what))
    }

    fn send(&self, py: Python<'_>, (done, total): (usize, usize), last: bool) -> PyResult<()> {
        match self {
            Sink::Call(f) => f.call1((done, total)).map(drop),
            Sink::Stderr(what) => {
                let end = if last { "\n" } else { "" };
                let err = py.import("sys")?.getattr("stderr")?;
                err.call_method1("write", (format!("\r{what}: {done}/{total} runs{end}"),))?;
                err.call_method0("flush").map(drop)
            }
        }
    }
}

/// Runs `work` with the GIL released on a scoped thread, reporting its
/// progress (`progress`: None, a callable `f(done, total)`, or `True` for a
/// line on stderr naming `what`) and stopping it on Ctrl-C. `work` must
/// check [`Control::cancel`] often and call [`Control::report`]. Returns
/// what `work` returned, or the Python exception (`KeyboardInterrupt`, or
/// one the progress callback raised) after the work has stopped.
pub(crate) fn run<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    what: &'static str,
    work: impl FnOnce(&Control) -> T + Send,
) -> PyResult<T> {
    let sink = Sink::of(progress, what);
    let control = Control::default();
    std::thread::scope(|scope| {
        // A main thread's stack for the work (which may run Python
        // components, e.g. NumPy's threaded OpenBLAS; see
        // `hil_jobs::WORKER_STACK_BYTES`).
        let handle = std::thread::Builder::new()
            .stack_size(hil_jobs::WORKER_STACK_BYTES)
            .spawn_scoped(scope, || work(&control))
            .map_err(|e| {
                crate::errors::to_py_err(hil_core::HilError::state(what, e.to_string()))
            })?;
        let mut reported = (0, 0);
        let mut raised = None;
        loop {
            let finished = py.detach(|| {
                let until = std::time::Instant::now() + POLL;
                while !handle.is_finished() && std::time::Instant::now() < until {
                    std::thread::sleep(Duration::from_millis(5));
                }
                handle.is_finished()
            });
            let now = control.progress();
            if let Some(sink) = &sink
                && now != reported
                && now.1 > 0
            {
                reported = now;
                if let Err(e) = sink.send(py, now, finished && now.0 == now.1) {
                    raised = Some(e);
                }
            }
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                raised = Some(e);
            }
            if raised.is_some() {
                control.cancel.store(true, Ordering::Relaxed);
            }
            if finished || raised.is_some() {
                break;
            }
        }
        let out = py.detach(|| handle.join());
        match (raised, out) {
            (Some(e), _) => Err(e),
            (None, Ok(v)) => Ok(v),
            (None, Err(_)) => Err(pyo3::exceptions::PyRuntimeError::new_err(format!(
                "{what}: the run panicked (a bug in hil; please report it)"
            ))),
        }
    })
}

/// A session observer that ends the session at the next boundary between
/// steps once the caller asked to stop: after a step's outcome is recorded,
/// or before an item or episode starts (never between a recorded step and
/// its outcome). Put it after the recorder, which has then written the step.
pub(crate) struct StopAtBoundary<'c>(pub(crate) &'c Control);

impl StopAtBoundary<'_> {
    /// An error ending the session when a stop was asked for (the caller
    /// raises the Python exception that asked; this error only ends the work).
    fn check(&self) -> hil_core::Result<()> {
        if self.0.cancelled() {
            Err(HilError::state("session", "interrupted from Python"))
        } else {
            Ok(())
        }
    }
}

impl SessionObserver for StopAtBoundary<'_> {
    fn on_episode_start(&mut self, _: u64) -> hil_core::Result<()> {
        self.check()
    }
    fn on_item_start(&mut self, _: &Item) -> hil_core::Result<()> {
        self.check()
    }
    fn on_step(&mut self, _: &StepEvent) -> hil_core::Result<()> {
        self.check()
    }
}
