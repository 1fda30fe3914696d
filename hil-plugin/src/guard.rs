//! Panic guards around everything a plugin hands to the host.
//!
//! A panic must not unwind out of a plugin: the plugin carries its own copy
//! of the standard library, and unwinding from one copy into another is
//! undefined (in practice, an abort). So every factory and every trait
//! method of every object a plugin returns runs under `catch_unwind`
//! *inside the plugin* (these wrappers are instantiated by the plugin's
//! registration code, see [`super::Registrar`]), and a panic becomes a
//! [`HilError::Plugin`].
//!
//! After a panic an object's state is unknown, so the wrapper is poisoned:
//! every later call returns an error saying where the first panic happened.
//! Methods that cannot return an error either read values cached when the
//! object was built (`name`, `n_arms`, `dim`, `action_space`,
//! `context_dim`) or answer "nothing" (`best_action`, `current_item` return
//! `None`) and poison the object, so the next fallible call reports it.
//!
//! A destructor cannot return an error, so a panic while a plugin object is
//! dropped is sent to the host's [`DropPanicSink`] (which the host hands
//! over through [`super::PluginRegistrar::drop_panic_sink`]) and collected
//! there until the host asks for it with [`take_destructor_panics`]: `hil`
//! reports it as an error after the run, instead of carrying on silently.
//!
//! A caught panic is not printed: while a guard runs a call, the panic hook
//! of the standard library the call runs in (the plugin's own copy) only
//! records where the panic happened, and the backtrace when
//! `RUST_BACKTRACE` asks for one, and the error carries both. So a report
//! says it once, in its place, instead of the default hook printing it to
//! stderr at every panic. Panics outside a guard go to the previous hook.

use std::any::Any;
use std::backtrace::{Backtrace, BacktraceStatus};
use std::cell::{Cell, RefCell};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once, OnceLock};
use std::thread::ThreadId;

use serde_json::Value;

use hil_core::error::{HilError, Result};
use hil_core::{
    ActionSpace, ArmId, Context, Decision, DecisionInput, Environment, Feedback, Item, Outcome,
    Policy, Query, QueryChannel, QueryKind, Response, WorkloadInput, WorkloadModel,
};

/// The message of a panic payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(a panic with a non-string payload)".to_string()
    }
}

/// A panic caught by a guard: its message, and where it happened as the
/// panic hook saw it.
pub(crate) struct Panic {
    message: String,
    /// `file:line:column`, when the hook saw the panic.
    location: Option<String>,
    /// Captured when `RUST_BACKTRACE` (or `RUST_LIB_BACKTRACE`) asks for it.
    backtrace: Option<Backtrace>,
}

impl Panic {
    /// The message, then where it happened (and the backtrace, if any).
    pub(crate) fn describe(&self) -> String {
        let mut s = self.message.clone();
        if let Some(at) = &self.location {
            s.push_str(&format!(" (at {at})"));
        }
        if let Some(bt) = &self.backtrace {
            s.push_str(&format!("\nbacktrace:\n{bt}"));
        }
        s
    }
}

/// What the hook saw of the last panic on this thread inside a guard.
struct Seen {
    location: Option<String>,
    backtrace: Option<Backtrace>,
}

thread_local! {
    /// How many guarded calls this thread is inside.
    static GUARDED: Cell<usize> = const { Cell::new(0) };
    /// The hook's record of the panic being unwound.
    static SEEN: RefCell<Option<Seen>> = const { RefCell::new(None) };
}

/// Installs (once per copy of the standard library) the hook that records
/// a guarded panic instead of printing it, and leaves every other panic to
/// the hook that was there before.
fn install_hook() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if GUARDED.try_with(Cell::get).unwrap_or(0) == 0 {
                return previous(info);
            }
            let backtrace = Backtrace::capture();
            let seen = Seen {
                location: info.location().map(ToString::to_string),
                backtrace: (backtrace.status() == BacktraceStatus::Captured).then_some(backtrace),
            };
            let _ = SEEN.try_with(|s| *s.borrow_mut() = Some(seen));
        }));
    });
}

/// Runs `f`, catching a panic (recorded by the hook, not printed). The one
/// `catch_unwind` of the guards.
pub(crate) fn catch<T>(f: impl FnOnce() -> T) -> std::result::Result<T, Panic> {
    install_hook();
    GUARDED.with(|g| g.set(g.get() + 1));
    let r = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(g.get() - 1));
    r.map_err(|payload| {
        let seen = SEEN.with(|s| s.borrow_mut().take());
        Panic {
            message: panic_message(&*payload),
            location: seen.as_ref().and_then(|s| s.location.clone()),
            backtrace: seen.and_then(|s| s.backtrace),
        }
    })
}

fn panicked(lib: &Path, name: &str, method: &str, panic: &Panic) -> HilError {
    HilError::Plugin {
        path: lib.to_path_buf(),
        why: format!("`{name}{PANICKED}{method}: {}", panic.describe()),
    }
}

/// The method a guarded panic happened in, read from the error a guard
/// made of it ([`HilError::Plugin`] saying `panicked in METHOD: ...`, or,
/// for a later call on the poisoned object, `panicked earlier, in
/// METHOD: ...`); `None` for any other error.
///
/// ```
/// use hil_core::HilError;
/// let e = hil_plugin::call_guarded(std::path::Path::new("lib.so"), "p", "seed", || -> hil_core::Result<()> {
///     panic!("no seed")
/// }).unwrap_err();
/// assert_eq!(hil_plugin::panicked_in(&e).as_deref(), Some("seed"));
/// assert_eq!(hil_plugin::panicked_in(&HilError::state("p", "late")), None);
/// ```
pub fn panicked_in(e: &HilError) -> Option<String> {
    let HilError::Plugin { why, .. } = e else {
        return None;
    };
    let (_, rest) = why
        .split_once(POISONED)
        .or_else(|| why.split_once(PANICKED))?;
    rest.split_once(':').map(|(method, _)| method.to_string())
}

/// What a guard's error says before the method that panicked (read back
/// by [`panicked_in`]).
const PANICKED: &str = "` panicked in ";
/// The same, on a call to an object poisoned by an earlier panic.
const POISONED: &str = "it panicked earlier, in ";

/// Where a panic in a plugin object's destructor is reported: a plain
/// function of the host's, so that the error lands in the host's copy of
/// hil-core whichever copy (the plugin's) ran the destructor.
pub type DropPanicSink = fn(HilError);

/// The destructor panics reported so far, with the thread that dropped the
/// object, in the copy of hil-plugin that owns this static (the host's,
/// through [`report_drop_panic`]).
static DROP_PANICS: Mutex<Vec<(ThreadId, HilError)>> = Mutex::new(Vec::new());

fn drop_panics() -> std::sync::MutexGuard<'static, Vec<(ThreadId, HilError)>> {
    DROP_PANICS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The host's [`DropPanicSink`]: remembers the error for
/// [`take_destructor_panics`].
pub fn report_drop_panic(error: HilError) {
    drop_panics().push((std::thread::current().id(), error));
}

/// Takes the errors of every plugin destructor that panicked since the last
/// call (a [`HilError::Plugin`] each, naming the library, the type and
/// `drop`). A host calls it once it has dropped its plugin objects.
///
/// ```
/// assert!(hil_plugin::take_destructor_panics().is_empty());
/// ```
pub fn take_destructor_panics() -> Vec<HilError> {
    std::mem::take(&mut *drop_panics())
        .into_iter()
        .map(|(_, e)| e)
        .collect()
}

/// Takes the destructor panics of objects dropped on this thread since the
/// last call, leaving other threads' for them: what a conformance suite,
/// which builds and drops its objects on the calling thread, reads while
/// other suites run on other threads.
///
/// ```
/// assert!(hil_plugin::take_destructor_panics_on_this_thread().is_empty());
/// ```
pub fn take_destructor_panics_on_this_thread() -> Vec<HilError> {
    let here = std::thread::current().id();
    let mut all = drop_panics();
    let (mine, others) = std::mem::take(&mut *all)
        .into_iter()
        .partition(|(id, _)| *id == here);
    *all = others;
    mine.into_iter().map(|(_, e)| e).collect()
}

/// Runs `f` for the object `name` of library `lib`, turning a panic in
/// `method` into a [`HilError::Plugin`] that carries the panic's message,
/// location (and backtrace, when `RUST_BACKTRACE` asks for one) instead of
/// printing them.
pub fn call<T>(lib: &Path, name: &str, method: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    catch(f).unwrap_or_else(|p| Err(panicked(lib, name, method, &p)))
}

/// Where an object came from and whether it has panicked.
#[derive(Debug)]
struct Guard {
    library: PathBuf,
    name: String,
    /// The method and message of the first panic.
    poisoned: OnceLock<String>,
    /// Where a panic in the destructor goes.
    on_drop_panic: DropPanicSink,
}

impl Guard {
    fn new(library: PathBuf, name: &str) -> Self {
        Self {
            library,
            name: name.to_string(),
            poisoned: OnceLock::new(),
            on_drop_panic: report_drop_panic,
        }
    }

    /// Drops a plugin object under the guard: a panicking destructor is
    /// reported to the sink as this object's panic in `drop`.
    fn drop_guarded<T>(&self, inner: Option<T>) {
        if let Err(p) = catch(move || drop(inner)) {
            (self.on_drop_panic)(panicked(&self.library, &self.name, "drop", &p));
        }
    }

    fn check(&self) -> Result<()> {
        match self.poisoned.get() {
            None => Ok(()),
            Some(first) => Err(HilError::Plugin {
                path: self.library.clone(),
                why: format!("`{}` is unusable: {POISONED}{first}", self.name),
            }),
        }
    }

    /// Poisons the object; the later errors name the method, message and
    /// location (the backtrace is in this panic's own error only).
    fn poison(&self, method: &str, panic: &Panic) -> HilError {
        let at = panic
            .location
            .as_ref()
            .map(|l| format!(" (at {l})"))
            .unwrap_or_default();
        let _ = self
            .poisoned
            .set(format!("{method}: {}{at}", panic.message));
        panicked(&self.library, &self.name, method, panic)
    }

    /// A fallible call.
    fn run<T>(&self, method: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        self.check()?;
        catch(f).unwrap_or_else(|p| Err(self.poison(method, &p)))
    }

    /// An infallible call: a panic poisons and yields `fallback`.
    fn run_or<T>(&self, method: &str, fallback: T, f: impl FnOnce() -> T) -> T {
        if self.check().is_err() {
            return fallback;
        }
        catch(f).unwrap_or_else(|p| {
            self.poison(method, &p);
            fallback
        })
    }

    fn gone(&self) -> HilError {
        HilError::state(&self.name, "the object was already dropped")
    }
}

/// Reads values to cache from a new object; if that panics, the object is
/// dropped under the guard too and the panic is the error.
fn cache<O, T>(guard: &Guard, method: &str, inner: O, f: impl FnOnce(&O) -> T) -> Result<(O, T)> {
    match guard.run(method, || Ok(f(&inner))) {
        Ok(v) => Ok((inner, v)),
        Err(e) => {
            guard.drop_guarded(Some(inner));
            Err(e)
        }
    }
}

/// A plugin object of trait `T` behind a panic guard, with the values that
/// the trait's infallible methods return cached at construction (`F`).
pub struct Guarded<T: ?Sized, F = ()> {
    inner: Option<Box<T>>,
    guard: Guard,
    name: String,
    facts: F,
}

/// A plugin [`Policy`] behind a panic guard (caches `n_arms` and `dim`).
pub type GuardedPolicy = Guarded<dyn Policy, (usize, usize)>;
/// A plugin [`Environment`] behind a panic guard (caches the action space
/// and the context dimension).
pub type GuardedEnvironment = Guarded<dyn Environment, (ActionSpace, usize)>;
/// A plugin [`WorkloadModel`] behind a panic guard.
pub type GuardedWorkload = Guarded<dyn WorkloadModel>;
/// A plugin [`QueryChannel`] behind a panic guard.
pub type GuardedChannel = Guarded<dyn QueryChannel>;

impl<T: ?Sized, F> std::fmt::Debug for Guarded<T, F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Guarded")
            .field("name", &self.name)
            .field("guard", &self.guard)
            .finish_non_exhaustive()
    }
}

impl<T: ?Sized, F> Guarded<T, F> {
    /// Wraps `inner`, reading its name and facts under the guard (a panic
    /// there is an error, and the object is dropped under the guard).
    fn wrap(
        inner: Box<T>,
        library: PathBuf,
        type_name: &str,
        what: &str,
        read: impl FnOnce(&T) -> (String, F),
    ) -> Result<Self> {
        let guard = Guard::new(library, type_name);
        let (inner, (name, facts)) = cache(&guard, what, inner, |o| read(o))?;
        Ok(Self {
            inner: Some(inner),
            guard,
            name,
            facts,
        })
    }

    /// Runs a fallible method of the wrapped object under the guard.
    fn call<R>(&self, method: &str, f: impl FnOnce(&T) -> Result<R>) -> Result<R> {
        let o = self.inner.as_deref().ok_or_else(|| self.guard.gone())?;
        self.guard.run(method, || f(o))
    }

    /// Runs a fallible `&mut self` method of the wrapped object under the guard.
    fn call_mut<R>(&mut self, method: &str, f: impl FnOnce(&mut T) -> Result<R>) -> Result<R> {
        let o = self.inner.as_deref_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run(method, || f(o))
    }
}

impl<T: ?Sized, F> Guarded<T, F> {
    /// Sends a panic in the wrapped object's destructor to `sink` (by
    /// default, [`report_drop_panic`] of the copy of hil-core that built
    /// the wrapper; a plugin's registrar passes the host's).
    pub fn reporting_drop_panics_to(mut self, sink: DropPanicSink) -> Self {
        self.guard.on_drop_panic = sink;
        self
    }
}

impl<T: ?Sized, F> Drop for Guarded<T, F> {
    fn drop(&mut self) {
        let inner = self.inner.take();
        self.guard.drop_guarded(inner);
    }
}

impl GuardedPolicy {
    /// Wraps `inner`, caching its name and shape (a panic there is an error).
    pub fn new(inner: Box<dyn Policy>, library: PathBuf, type_name: &str) -> Result<Self> {
        Self::wrap(inner, library, type_name, "name/n_arms/dim", |p| {
            (p.name().to_string(), (p.n_arms(), p.dim()))
        })
    }
}

impl Policy for GuardedPolicy {
    fn name(&self) -> &str {
        &self.name
    }
    fn n_arms(&self) -> usize {
        self.facts.0
    }
    fn dim(&self) -> usize {
        self.facts.1
    }
    fn seed(&mut self, seed: u64) {
        if let Some(p) = self.inner.as_mut() {
            self.guard.run_or("seed", (), || p.seed(seed));
        }
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        self.call_mut("decide", |p| p.decide(input))
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        self.call_mut("observe", |p| p.observe(feedback))
    }
    fn save(&self) -> Result<Value> {
        self.call("save", |p| p.save())
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        self.call_mut("restore", |p| p.restore(state))
    }
}

impl GuardedEnvironment {
    /// Wraps `inner`, caching its name, action space and context dimension.
    pub fn new(inner: Box<dyn Environment>, library: PathBuf, type_name: &str) -> Result<Self> {
        Self::wrap(
            inner,
            library,
            type_name,
            "name/action_space/context_dim",
            |e| {
                (
                    e.name().to_string(),
                    (e.action_space().clone(), e.context_dim()),
                )
            },
        )
    }
}

impl Environment for GuardedEnvironment {
    fn name(&self) -> &str {
        &self.name
    }
    fn action_space(&self) -> &ActionSpace {
        &self.facts.0
    }
    fn context_dim(&self) -> usize {
        self.facts.1
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.call_mut("reset", |e| e.reset(seed))
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        self.call_mut("next_item", |e| e.next_item())
    }
    fn observe(&mut self) -> Result<Context> {
        self.call_mut("observe", |e| e.observe())
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.call_mut("execute", |e| e.execute(arm))
    }
    fn best_action(&self) -> Option<ArmId> {
        let e = self.inner.as_ref()?;
        self.guard.run_or("best_action", None, || e.best_action())
    }
    fn current_item(&self) -> Option<&Item> {
        let e = self.inner.as_ref()?;
        self.guard.run_or("current_item", None, || e.current_item())
    }
}

impl GuardedWorkload {
    /// Wraps `inner`, caching its name.
    pub fn new(inner: Box<dyn WorkloadModel>, library: PathBuf, type_name: &str) -> Result<Self> {
        Self::wrap(inner, library, type_name, "name", |m| {
            (m.name().to_string(), ())
        })
    }
}

impl WorkloadModel for GuardedWorkload {
    fn name(&self) -> &str {
        &self.name
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        self.call("predict", |m| m.predict(input))
    }
    fn predict_if_queried(&self, input: &WorkloadInput<'_>, kind: QueryKind) -> Result<f64> {
        self.call("predict_if_queried", |m| m.predict_if_queried(input, kind))
    }
}

impl GuardedChannel {
    /// Wraps `inner`, caching its name.
    pub fn new(inner: Box<dyn QueryChannel>, library: PathBuf, type_name: &str) -> Result<Self> {
        Self::wrap(inner, library, type_name, "name", |c| {
            (c.name().to_string(), ())
        })
    }
}

impl QueryChannel for GuardedChannel {
    fn name(&self) -> &str {
        &self.name
    }
    fn seed(&mut self, seed: u64) {
        if let Some(c) = self.inner.as_mut() {
            self.guard.run_or("seed", (), || c.seed(seed));
        }
    }
    fn ask(&mut self, query: &Query) -> Result<Response> {
        self.call_mut("ask", |c| c.ask(query))
    }
}
