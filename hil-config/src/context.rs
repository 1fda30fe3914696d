//! What component factories are built from: [`BuildContext`],
//! [`TaskContext`] and the build-wide [`BuildMemo`].

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hil_core::{ActionSpace, HilError, LabelledObservation, Result};

/// What every component factory may need: where relative paths resolve,
/// the experiment seed and the build-wide memo. Environments and workload
/// models are built from this alone; policies and query channels from a
/// [`TaskContext`], which adds the built environment's facts.
#[derive(Clone, Debug)]
pub struct BuildContext {
    /// Directory relative paths in the config are resolved against.
    pub base_dir: PathBuf,
    /// The experiment seed.
    pub seed: u64,
    /// Work shared by every component built from this context (and its
    /// clones): a protocol that builds hundreds of policies from one context
    /// pretrains each distinct estimator once.
    pub memo: Arc<BuildMemo>,
}

/// What policy and query-channel factories are built from: the
/// [`BuildContext`] plus the facts of the environment they will act in.
/// Every fact is known, so a factory never has to check for a missing one;
/// [`BuildContext::describe_environment`] makes it from a built environment.
///
/// ```
/// use hil_core::ActionSpace;
/// use hil_config::{BuildContext, TaskContext};
/// let actions = ActionSpace::new(["left", "right"]).unwrap();
/// let ctx = TaskContext::new(BuildContext::new(".", 7), actions, 4);
/// assert_eq!((ctx.action_space().len(), ctx.context_dim(), ctx.base().seed), (2, 4, 7));
/// assert!(ctx.pretraining().is_none());
/// ```
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct TaskContext {
    base: BuildContext,
    action_space: ActionSpace,
    context_dim: usize,
    pretraining: Option<Arc<[LabelledObservation]>>,
}

impl TaskContext {
    /// The context for components acting among `action_space` on contexts of
    /// dimension `context_dim`, with no pretraining data.
    pub fn new(base: BuildContext, action_space: ActionSpace, context_dim: usize) -> Self {
        Self {
            base,
            action_space,
            context_dim,
            pretraining: None,
        }
    }

    /// With offline (context, arm, reward) data for pretraining policies.
    pub fn with_pretraining(mut self, data: Arc<[LabelledObservation]>) -> Self {
        self.pretraining = Some(data);
        self
    }

    /// Paths, seed and memo.
    pub fn base(&self) -> &BuildContext {
        &self.base
    }

    /// The environment's action space.
    pub fn action_space(&self) -> &ActionSpace {
        &self.action_space
    }

    /// The environment's context dimension.
    pub fn context_dim(&self) -> usize {
        self.context_dim
    }

    /// The offline data the environment offers for pretraining (see
    /// [`EnvironmentConfig::pretraining`](crate::EnvironmentConfig::pretraining)), if any.
    pub fn pretraining(&self) -> Option<&Arc<[LabelledObservation]>> {
        self.pretraining.as_ref()
    }

    /// The pretraining data for a policy whose config asks for it
    /// (`pretrain = true`); without any, an error naming `pretrain` that
    /// says how an environment comes to offer some.
    pub fn required_pretraining(&self) -> Result<&Arc<[LabelledObservation]>> {
        self.pretraining().ok_or_else(|| {
            HilError::invalid_parameter(
                "pretrain",
                true,
                "pretraining was requested but the environment offers no pretraining data: \
                 configure the environment to offer some (`pretraining_trials` of a \
                 `kinova_feeding` environment, `pretrain_foods` of a `food_replay` one), or set `pretrain = false`",
            )
        })
    }

    /// Resolves `path` against the config's directory unless it is absolute.
    pub fn resolve(&self, path: &Path) -> PathBuf {
        self.base.resolve(path)
    }
}

/// A cache of values derived from a [`BuildContext`] (e.g. an estimator
/// pretrained on its `pretraining` data), keyed by a string that must name
/// everything the value depends on besides the context itself.
///
/// ```
/// let ctx = hil_config::BuildContext::new(".", 0);
/// let a: u32 = ctx.memo.get_or_try_insert("answer", || Ok(42)).unwrap();
/// let b: u32 = ctx.clone().memo.get_or_try_insert("answer", || Ok(0)).unwrap();
/// assert_eq!((a, b), (42, 42));
/// ```
#[derive(Default)]
pub struct BuildMemo {
    values:
        std::sync::Mutex<std::collections::HashMap<String, Arc<dyn std::any::Any + Send + Sync>>>,
}

impl std::fmt::Debug for BuildMemo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.values.lock().map_or(0, |m| m.len());
        f.debug_struct("BuildMemo").field("values", &n).finish()
    }
}

impl BuildMemo {
    /// The value under `key`, computed by `make` the first time. The lock is
    /// held while `make` runs, so concurrent builders compute it once. A
    /// value of another type under the same key is an error.
    pub fn get_or_try_insert<T, F>(&self, key: &str, make: F) -> Result<T>
    where
        T: Clone + Send + Sync + 'static,
        F: FnOnce() -> Result<T>,
    {
        let mut values = self.values.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(v) = values.get(key) {
            return v.downcast_ref::<T>().cloned().ok_or_else(|| {
                HilError::state(
                    "build memo",
                    format!("the value under `{key}` has another type"),
                )
            });
        }
        let v = make()?;
        values.insert(key.to_string(), Arc::new(v.clone()));
        Ok(v)
    }
}

impl BuildContext {
    /// A context resolving paths against `base_dir`.
    pub fn new(base_dir: impl Into<PathBuf>, seed: u64) -> Self {
        Self {
            base_dir: base_dir.into(),
            seed,
            memo: Arc::default(),
        }
    }

    /// Resolves `path` against the config's directory unless it is absolute.
    pub fn resolve(&self, path: &Path) -> PathBuf {
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.base_dir.join(path)
        }
    }
}
