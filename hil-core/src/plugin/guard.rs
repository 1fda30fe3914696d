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

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;

use crate::error::{HilError, Result};
use crate::{
    ActionSpace, ArmId, Context, Decision, DecisionInput, Environment, Feedback, Item, Outcome,
    Policy, Query, QueryChannel, QueryHistory, QueryKind, Response, Timestep, WorkloadModel,
};

/// The message of a panic payload.
pub(crate) fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(a panic with a non-string payload)".to_string()
    }
}

fn panicked(lib: &Path, name: &str, method: &str, payload: &(dyn Any + Send)) -> HilError {
    HilError::Plugin {
        path: lib.to_path_buf(),
        why: format!("`{name}` panicked in {method}: {}", panic_message(payload)),
    }
}

/// Runs `f`, turning a panic into a [`HilError::Plugin`].
pub(crate) fn call<T>(
    lib: &Path,
    name: &str,
    method: &str,
    f: impl FnOnce() -> Result<T>,
) -> Result<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| Err(panicked(lib, name, method, &*p)))
}

/// Where an object came from and whether it has panicked.
#[derive(Debug)]
struct Guard {
    library: PathBuf,
    name: String,
    /// The method and message of the first panic.
    poisoned: OnceLock<String>,
}

impl Guard {
    fn new(library: PathBuf, name: &str) -> Self {
        Self {
            library,
            name: name.to_string(),
            poisoned: OnceLock::new(),
        }
    }

    fn check(&self) -> Result<()> {
        match self.poisoned.get() {
            None => Ok(()),
            Some(first) => Err(HilError::Plugin {
                path: self.library.clone(),
                why: format!(
                    "`{}` is unusable: it panicked earlier, in {first}",
                    self.name
                ),
            }),
        }
    }

    fn poison(&self, method: &str, payload: &(dyn Any + Send)) -> HilError {
        let _ = self
            .poisoned
            .set(format!("{method}: {}", panic_message(payload)));
        panicked(&self.library, &self.name, method, payload)
    }

    /// A fallible call.
    fn run<T>(&self, method: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        self.check()?;
        catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| Err(self.poison(method, &*p)))
    }

    /// An infallible call: a panic poisons and yields `fallback`.
    fn run_or<T>(&self, method: &str, fallback: T, f: impl FnOnce() -> T) -> T {
        if self.check().is_err() {
            return fallback;
        }
        catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| {
            self.poison(method, &*p);
            fallback
        })
    }

    fn gone(&self) -> HilError {
        HilError::state(&self.name, "the object was already dropped")
    }
}

/// Drops a plugin object under the guard: a panicking destructor is
/// reported by the plugin's panic hook and otherwise ignored.
fn drop_guarded<T>(inner: Option<T>) {
    let _ = catch_unwind(AssertUnwindSafe(move || drop(inner)));
}

/// Reads values to cache from a new object; if that panics, the object is
/// dropped under the guard too and the panic is the error.
fn cache<O, T>(guard: &Guard, method: &str, inner: O, f: impl FnOnce(&O) -> T) -> Result<(O, T)> {
    match guard.run(method, || Ok(f(&inner))) {
        Ok(v) => Ok((inner, v)),
        Err(e) => {
            drop_guarded(Some(inner));
            Err(e)
        }
    }
}

/// A plugin [`Policy`] behind a panic guard.
pub struct GuardedPolicy {
    inner: Option<Box<dyn Policy>>,
    guard: Guard,
    name: String,
    n_arms: usize,
    dim: usize,
}

impl std::fmt::Debug for GuardedPolicy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GuardedPolicy")
            .field("name", &self.name)
            .field("guard", &self.guard)
            .finish_non_exhaustive()
    }
}

impl GuardedPolicy {
    /// Wraps `inner`, caching its name and shape (a panic there is an error).
    pub fn new(inner: Box<dyn Policy>, library: PathBuf, type_name: &str) -> Result<Self> {
        let guard = Guard::new(library, type_name);
        let (inner, (name, n_arms, dim)) = cache(&guard, "name/n_arms/dim", inner, |p| {
            (p.name().to_string(), p.n_arms(), p.dim())
        })?;
        Ok(Self {
            inner: Some(inner),
            guard,
            name,
            n_arms,
            dim,
        })
    }
}

impl Policy for GuardedPolicy {
    fn name(&self) -> &str {
        &self.name
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        if let Some(p) = self.inner.as_mut() {
            self.guard.run_or("seed", (), || p.seed(seed));
        }
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let p = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("decide", || p.decide(input))
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        let p = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("observe", || p.observe(feedback))
    }
    fn save(&self) -> Result<Value> {
        let p = self.inner.as_ref().ok_or_else(|| self.guard.gone())?;
        self.guard.run("save", || p.save())
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let p = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("restore", || p.restore(state))
    }
}

impl Drop for GuardedPolicy {
    fn drop(&mut self) {
        drop_guarded(self.inner.take());
    }
}

/// A plugin [`Environment`] behind a panic guard.
pub struct GuardedEnvironment {
    inner: Option<Box<dyn Environment>>,
    guard: Guard,
    name: String,
    actions: ActionSpace,
    dim: usize,
}

impl std::fmt::Debug for GuardedEnvironment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GuardedEnvironment")
            .field("name", &self.name)
            .field("guard", &self.guard)
            .finish_non_exhaustive()
    }
}

impl GuardedEnvironment {
    /// Wraps `inner`, caching its name, action space and context dimension.
    pub fn new(inner: Box<dyn Environment>, library: PathBuf, type_name: &str) -> Result<Self> {
        let guard = Guard::new(library, type_name);
        let (inner, (name, actions, dim)) =
            cache(&guard, "name/action_space/context_dim", inner, |e| {
                (
                    e.name().to_string(),
                    e.action_space().clone(),
                    e.context_dim(),
                )
            })?;
        Ok(Self {
            inner: Some(inner),
            guard,
            name,
            actions,
            dim,
        })
    }
}

impl Environment for GuardedEnvironment {
    fn name(&self) -> &str {
        &self.name
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        self.dim
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        let e = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("reset", || e.reset(seed))
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        let e = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("next_item", || e.next_item())
    }
    fn observe(&mut self) -> Result<Context> {
        let e = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("observe", || e.observe())
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        let e = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("execute", || e.execute(arm))
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

impl Drop for GuardedEnvironment {
    fn drop(&mut self) {
        drop_guarded(self.inner.take());
    }
}

/// A plugin [`WorkloadModel`] behind a panic guard.
pub struct GuardedWorkload {
    inner: Option<Box<dyn WorkloadModel>>,
    guard: Guard,
    name: String,
}

impl std::fmt::Debug for GuardedWorkload {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GuardedWorkload")
            .field("name", &self.name)
            .field("guard", &self.guard)
            .finish_non_exhaustive()
    }
}

impl GuardedWorkload {
    /// Wraps `inner`, caching its name.
    pub fn new(inner: Box<dyn WorkloadModel>, library: PathBuf, type_name: &str) -> Result<Self> {
        let guard = Guard::new(library, type_name);
        let (inner, name) = cache(&guard, "name", inner, |o| o.name().to_string())?;
        Ok(Self {
            inner: Some(inner),
            guard,
            name,
        })
    }
}

impl WorkloadModel for GuardedWorkload {
    fn name(&self) -> &str {
        &self.name
    }
    fn predict(&self, wl0: f64, history: &QueryHistory, t: Timestep) -> Result<f64> {
        let m = self.inner.as_ref().ok_or_else(|| self.guard.gone())?;
        self.guard.run("predict", || m.predict(wl0, history, t))
    }
    fn predict_if_queried(
        &self,
        wl0: f64,
        history: &QueryHistory,
        t: Timestep,
        kind: QueryKind,
    ) -> Result<f64> {
        let m = self.inner.as_ref().ok_or_else(|| self.guard.gone())?;
        self.guard.run("predict_if_queried", || {
            m.predict_if_queried(wl0, history, t, kind)
        })
    }
}

impl Drop for GuardedWorkload {
    fn drop(&mut self) {
        drop_guarded(self.inner.take());
    }
}

/// A plugin [`QueryChannel`] behind a panic guard.
pub struct GuardedChannel {
    inner: Option<Box<dyn QueryChannel>>,
    guard: Guard,
    name: String,
}

impl std::fmt::Debug for GuardedChannel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GuardedChannel")
            .field("name", &self.name)
            .field("guard", &self.guard)
            .finish_non_exhaustive()
    }
}

impl GuardedChannel {
    /// Wraps `inner`, caching its name.
    pub fn new(inner: Box<dyn QueryChannel>, library: PathBuf, type_name: &str) -> Result<Self> {
        let guard = Guard::new(library, type_name);
        let (inner, name) = cache(&guard, "name", inner, |o| o.name().to_string())?;
        Ok(Self {
            inner: Some(inner),
            guard,
            name,
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
        let c = self.inner.as_mut().ok_or_else(|| self.guard.gone())?;
        self.guard.run("ask", || c.ask(query))
    }
}

impl Drop for GuardedChannel {
    fn drop(&mut self) {
        drop_guarded(self.inner.take());
    }
}
