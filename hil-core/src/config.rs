//! Experiment configuration: TOML files whose components are named by type
//! through typetag, with errors that name the file, line and field.
//!
//! ```toml
//! seed = 7
//! episodes = 3
//!
//! [session]
//! n_att = 10
//! wl0 = 0.5
//!
//! [environment]
//! type = "food_replay"     # any registered EnvironmentConfig
//!
//! [policy]
//! type = "linucb_qg"
//! alpha = 0.1
//!
//! [workload]               # the model that evolves and scores workload
//! type = "granger"
//!
//! [channel]
//! type = "simulated_expert"
//! ```
//!
//! Crates register built-in types with `#[typetag::serde(name = "...")]` on
//! an `impl PolicyConfig for ...` (or the other three config traits). A
//! program holds the types of the crates linked into it, with no call to
//! make: `hil_experiments` links every built-in crate, so a program that
//! reads configs through `hil_experiments::load_experiment` (or uses that
//! crate at all) knows every built-in type. The names a program holds are
//! [`crate::plugin::builtin_types`]; a plugin cannot take one of them, and
//! an unknown `type` is answered with the closest built-in and plugin names.
//!
//! [`ExperimentConfig::parse`] checks the whole file before anything is
//! built: every count against the limits stated in [`limits`], and every
//! component's parameters through its config's `validate`. Any error is a
//! [`ConfigError`] naming the file, line and field, and quotes an offending
//! value shortened by [`crate::error::echo`].

pub mod limits;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::action::ActionSpace;
use crate::channel::QueryChannel;
use crate::decision::LabelledObservation;
use crate::environment::Environment;
use crate::error::{HilError, Result, echo};
use crate::policy::Policy;
use crate::session::SessionSettings;
use crate::workload::WorkloadModel;

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
/// use hil_core::{ActionSpace, BuildContext, TaskContext};
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
    /// [`EnvironmentConfig::pretraining`]), if any.
    pub fn pretraining(&self) -> Option<&Arc<[LabelledObservation]>> {
        self.pretraining.as_ref()
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
/// let ctx = hil_core::BuildContext::new(".", 0);
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
                crate::HilError::state(
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

    /// The context for the policy and channel of a built environment: its
    /// action space, its context dimension and the pretraining data its
    /// `config` offers. Every protocol that builds an environment and then
    /// the components around it goes through this, so they all see the same
    /// facts.
    pub fn describe_environment(
        &self,
        config: &dyn EnvironmentConfig,
        environment: &dyn Environment,
    ) -> Result<TaskContext> {
        let task = TaskContext::new(
            self.clone(),
            environment.action_space().clone(),
            environment.context_dim(),
        );
        Ok(match config.pretraining(self)? {
            Some(data) => task.with_pretraining(data),
            None => task,
        })
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

/// A serialisable recipe for a [`Policy`].
#[typetag::serde(tag = "type")]
pub trait PolicyConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the policy for the environment
    /// described by `ctx`.
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn Policy>>;

    /// Checks the parameters that need no environment. A config loader
    /// ([`ExperimentConfig::parse`]) calls it on every component it reads
    /// and turns an error into a [`ConfigError`] naming the file, line and
    /// field ([`ConfigError::from_error`]); `build` must check them too
    /// (calling this is the simplest way). It must be cheap: no I/O and
    /// nothing allocated in proportion to a count (check counts against
    /// [`limits`]). The default accepts everything.
    fn validate(&self) -> Result<()> {
        Ok(())
    }

    /// Whether the policy's decisions read the workload forecast. A protocol
    /// runs a policy that does not once and scores it under every workload
    /// model; one that does runs once per deciding model. The default
    /// (`true`) is the safe assumption for a policy nobody described.
    fn uses_workload_forecast(&self) -> bool {
        true
    }

    /// Whether the policy's decisions depend on its own seed
    /// ([`Policy::seed`]). A protocol runs a stochastic policy under several
    /// policy seeds. The default (`true`) is the safe assumption.
    fn is_stochastic(&self) -> bool {
        true
    }
}

/// A serialisable recipe for an [`Environment`].
#[typetag::serde(tag = "type")]
pub trait EnvironmentConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the environment.
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Environment>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }

    /// Offline data for pretraining policies (e.g. the pretraining foods of
    /// a dataset), handed to policy configs through
    /// [`TaskContext::pretraining`]. None by default.
    fn pretraining(&self, ctx: &BuildContext) -> Result<Option<Arc<[LabelledObservation]>>> {
        let _ = ctx;
        Ok(None)
    }
}

/// A serialisable recipe for a [`WorkloadModel`].
#[typetag::serde(tag = "type")]
pub trait WorkloadModelConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds (or loads) the model.
    fn build(&self, ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

/// A serialisable recipe for a [`QueryChannel`].
#[typetag::serde(tag = "type")]
pub trait QueryChannelConfig: std::fmt::Debug + Send + Sync {
    /// Validates the parameters and builds the channel.
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>>;

    /// Checks the parameters at load time; see [`PolicyConfig::validate`].
    fn validate(&self) -> Result<()> {
        Ok(())
    }
}

/// A complete experiment: the components and how to run them.
///
/// Read from TOML (see `examples/configs/` for the built-in types); here
/// with components registered in code, as a downstream crate would:
///
/// ```
/// use std::path::Path;
/// use hil_core::plugin::{self, Params};
/// use hil_core::testing::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
/// use hil_core::{ActionSpace, ArmId, Choice, ExperimentConfig, HilError, PerfectExpert};
///
/// plugin::register_static(Path::new("experiment-doc"), |r| {
///     r.environment("doc_plate", "two foods", |_p: &Params, _ctx| {
///         let actions = ActionSpace::new(["skewer", "scoop"])?;
///         Ok(Box::new(TableEnv::new(actions, vec![("pea", vec![0.2, 0.9]), ("cube", vec![0.8, 0.3])])?))
///     });
///     r.policy("doc_always_skewer", "always the first action", |_p, ctx| {
///         let first = vec![Choice::Act { arm: ArmId(0) }];
///         Ok(Box::new(ScriptedPolicy::new(ctx.action_space().len(), ctx.context_dim(), first)))
///     });
///     r.workload_model("doc_counting", "a step per query", |_p, _ctx| {
///         Ok(Box::new(CountingWorkload::new(0.1)))
///     });
///     r.query_channel("doc_expert", "the perfect expert", |_p, _ctx| {
///         Ok(Box::new(PerfectExpert::default()))
///     });
/// })?;
///
/// let text = r#"
/// seed = 3
/// episodes = 2
/// [session]
/// n_att = 2
/// [environment]
/// type = "doc_plate"
/// [policy]
/// type = "doc_always_skewer"
/// [workload]
/// type = "doc_counting"
/// [channel]
/// type = "doc_expert"
/// "#;
/// let config = ExperimentConfig::parse(text, Path::new("doc.toml"))?;
/// let mut experiment = config.build(Path::new("."))?;
/// let summary = experiment.run(&mut [], |_, _| {})?;
/// assert_eq!(summary.episodes.len(), 2);
/// assert!(summary.episodes.iter().all(|m| m.n_items == 2 && m.n_q == 0));
///
/// // A mistake is reported with the file, line and field.
/// let e = ExperimentConfig::parse(&text.replace("n_att = 2", "n_att = 0"), Path::new("doc.toml"));
/// assert!(e.unwrap_err().to_string().contains("doc.toml"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    /// Shared libraries to load before the components are built.
    #[serde(default)]
    pub plugins: Vec<PathBuf>,
    /// Master seed; episode `k` runs with a seed derived from it.
    #[serde(default)]
    pub seed: u64,
    /// Number of episodes (the policy keeps learning across them), 1 to
    /// [`limits::EPISODES`].
    #[serde(default = "one")]
    pub episodes: usize,
    /// Session-loop settings.
    #[serde(default)]
    pub session: SessionSettings,
    /// Where the robot acts.
    #[serde(deserialize_with = "crate::plugin::component")]
    pub environment: Box<dyn EnvironmentConfig>,
    /// Who decides.
    #[serde(deserialize_with = "crate::plugin::component")]
    pub policy: Box<dyn PolicyConfig>,
    /// The workload model that evolves and scores the person's workload.
    #[serde(deserialize_with = "crate::plugin::component")]
    pub workload: Box<dyn WorkloadModelConfig>,
    /// The model the policy forecasts with, if different from `workload`.
    #[serde(default, deserialize_with = "crate::plugin::optional_component")]
    pub policy_workload: Option<Box<dyn WorkloadModelConfig>>,
    /// How queries reach the expert.
    #[serde(deserialize_with = "crate::plugin::component")]
    pub channel: Box<dyn QueryChannelConfig>,
}

fn one() -> usize {
    1
}

impl ExperimentConfig {
    /// Reads and validates an experiment file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::files::read_text(path, crate::files::limits::CONFIG)?;
        Ok(Self::parse(&text, path)?)
    }

    /// Parses experiment TOML. `path` names the file in error messages, and
    /// the `plugins` it lists are resolved against its directory and loaded
    /// (see [`crate::plugin::load`]) before the components are parsed, so
    /// plugin types are usable wherever built-in ones are.
    pub fn parse(text: &str, path: &Path) -> std::result::Result<Self, ConfigError> {
        load_plugins(text, path)?;
        let cfg: Self = parse_toml(text, path)?;
        let located =
            |section: &[&str], e: HilError| ConfigError::from_error(text, path, section, e);
        limits::check_count("episodes", cfg.episodes, limits::EPISODES)
            .map_err(|e| located(&[], e))?;
        cfg.session
            .validate()
            .and_then(|()| check_session_limits(&cfg.session))
            .map_err(|e| located(&["session"], e))?;
        // Every component's parameters, before anything is built, so that a
        // bad value names its line (`build` checks them again).
        let components: [(&str, Result<()>); 5] = [
            ("environment", cfg.environment.validate()),
            ("policy", cfg.policy.validate()),
            ("workload", cfg.workload.validate()),
            (
                "policy_workload",
                cfg.policy_workload
                    .as_ref()
                    .map_or(Ok(()), |w| w.validate()),
            ),
            ("channel", cfg.channel.validate()),
        ];
        for (section, checked) in components {
            checked.map_err(|e| located(&[section], e))?;
        }
        Ok(cfg)
    }
}

/// Checks the counts of session settings against [`limits`]
/// (`n_att` ≤ [`limits::ATTEMPTS_PER_ITEM`], `max_items` ≤
/// [`limits::ITEMS_PER_EPISODE`]); every loader of session settings calls it
/// after [`SessionSettings::validate`].
pub fn check_session_limits(settings: &SessionSettings) -> Result<()> {
    limits::check_count("n_att", settings.n_att, limits::ATTEMPTS_PER_ITEM)?;
    if let Some(n) = settings.max_items {
        limits::check_count("max_items", n, limits::ITEMS_PER_EPISODE)?;
    }
    Ok(())
}

/// Loads the `plugins` a config file lists (a top-level `plugins` array),
/// relative to the file's directory. Call it before parsing the rest of a
/// config of your own that names plugin types.
pub fn load_plugins(text: &str, path: &Path) -> std::result::Result<(), ConfigError> {
    #[derive(Deserialize)]
    struct PluginsOnly {
        #[serde(default)]
        plugins: Vec<PathBuf>,
    }
    let pre: PluginsOnly = parse_toml(text, path)?;
    let base = path.parent().unwrap_or(Path::new(""));
    for p in &pre.plugins {
        let full = if p.is_absolute() {
            p.clone()
        } else {
            base.join(p)
        };
        crate::plugin::load(&full)
            .map_err(|e| ConfigError::at_key(text, path, &["plugins"], e.to_string()))?;
    }
    Ok(())
}

/// A configuration error, located in its file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{column}: {}{message}", path.display(), field.as_ref().map(|f| format!("field `{f}`: ")).unwrap_or_default())]
pub struct ConfigError {
    /// The file at fault.
    pub path: PathBuf,
    /// 1-based line (0 if unknown).
    pub line: usize,
    /// 1-based column (0 if unknown).
    pub column: usize,
    /// Dotted path of the field at fault, e.g. `policy.alpha`.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

/// Parses TOML into `T`, turning errors into located [`ConfigError`]s.
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &Path,
) -> std::result::Result<T, ConfigError> {
    toml::from_str(text).map_err(|e| ConfigError::from_toml(text, path, &e))
}

impl ConfigError {
    fn from_toml(text: &str, path: &Path, e: &toml::de::Error) -> Self {
        let message = e.message().trim().to_string();
        let span_start = e.span().map(|s| s.start);
        let (mut line, mut column) = span_start.map_or((0, 0), |s| line_col(text, s));
        let section = span_start.map(|s| section_at(text, s)).unwrap_or_default();
        // Name the field: serde names it for unknown/missing fields; otherwise
        // the span points at a key or value whose key we read from the text.
        let named = quoted_after(&message, "unknown field `")
            .or_else(|| quoted_after(&message, "missing field `"));
        let field = match (&named, span_start) {
            (Some(name), _) => {
                // typetag buffers a table and reports at its header: find the key.
                if let Some(l) = find_key_line(text, &section, name) {
                    line = l;
                    column = 1;
                }
                Some(join_path(&section, name))
            }
            (None, Some(s)) => match key_on_line(text, s) {
                Some(k) => Some(join_path(&section, &k)),
                // typetag buffers a table and reports a bad value at the table
                // header: find the key in the section whose value is the one
                // the message quotes.
                None => match offending_literal(&message)
                    .and_then(|lit| find_value_line(text, &section, &lit))
                {
                    Some((l, key)) => {
                        line = l;
                        column = 1;
                        Some(join_path(&section, &key))
                    }
                    None => (!section.is_empty()).then(|| section.join(".")),
                },
            },
            (None, None) => None,
        };
        if message.starts_with("unknown variant") && field.is_none() {
            column = column.max(1);
        }
        Self::new(path, line, column, field, &message)
    }

    /// The error `e` raised by validating the table at `section` of a config
    /// (`&[]` for the top level): an [`HilError::InvalidParameter`] is
    /// located at its parameter's key (a dotted name such as
    /// `response_time.sigma` is followed into nested tables), anything else
    /// at the section.
    ///
    /// ```
    /// use std::path::Path;
    /// use hil_core::{ConfigError, HilError};
    /// let text = "[session]\nn_att = 0\n";
    /// let e = HilError::invalid_parameter("n_att", 0, "must be at least 1");
    /// let c = ConfigError::from_error(text, Path::new("x.toml"), &["session"], e);
    /// assert_eq!((c.line, c.field.as_deref()), (2, Some("session.n_att")));
    /// ```
    pub fn from_error(text: &str, path: &Path, section: &[&str], e: HilError) -> Self {
        let message = e.to_string();
        let section: Vec<String> = section.iter().map(|s| s.to_string()).collect();
        let field = match parameter_error(&message) {
            Some((name, _)) => join_path(&section, name),
            None => section.join("."),
        };
        // From the top, so that a key inside an inline table (`policy = {
        // alpha = inf }`) is found at the table's line.
        let line = find_dotted_key_line(text, &[], &field)
            .or_else(|| {
                let s: Vec<&str> = section.iter().map(String::as_str).collect();
                find_header_line(text, &s)
            })
            .unwrap_or(0);
        let message = match parameter_error(&message) {
            Some((_, rest)) => format!("invalid value {rest}"),
            None => message,
        };
        let field = (!field.is_empty()).then_some(field);
        Self::new(path, line, usize::from(line > 0), field, &message)
    }

    /// An error about the key at `key_path` (e.g. `["policy", "alpha"]`).
    pub fn at_key(text: &str, path: &Path, key_path: &[&str], message: String) -> Self {
        let (section, key) = match key_path.split_last() {
            Some((k, s)) => (s.iter().map(|s| s.to_string()).collect::<Vec<_>>(), *k),
            None => (Vec::new(), ""),
        };
        let line = find_key_line(text, &section, key)
            .or_else(|| find_header_line(text, key_path))
            .unwrap_or(0);
        Self::new(
            path,
            line,
            if line > 0 { 1 } else { 0 },
            Some(key_path.join(".")),
            &message,
        )
    }

    /// Every constructor ends here: the field and any value the message
    /// quotes are shortened by [`echo`], so a 100 KB key or value never
    /// becomes a 100 KB message.
    fn new(path: &Path, line: usize, column: usize, field: Option<String>, message: &str) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            column,
            field: field.map(|f| echo(&f).into_owned()),
            message: echo_quoted(message),
        }
    }
}

/// The prefix of [`HilError::InvalidParameter`]'s message.
const PARAMETER_PREFIX: &str = "invalid parameter `";

/// The parameter an [`HilError::InvalidParameter`] message names, and the
/// message from its value on (`invalid value 0: must be ...`).
fn parameter_error(message: &str) -> Option<(&str, &str)> {
    let rest = message.strip_prefix(PARAMETER_PREFIX)?;
    let (name, rest) = rest.split_once('`')?;
    let rest = rest.strip_prefix(" = ").unwrap_or(rest);
    Some((name, rest))
}

/// `message` with every `` `quoted` `` or `"quoted"` part shortened by
/// [`echo`]; a message still longer than a few values (unbalanced quotes) is
/// shortened as a whole.
fn echo_quoted(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(1024));
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = &rest[open..open + 1];
        let Some(len) = rest[open + 1..].find(quote) else {
            break;
        };
        let inner = &rest[open + 1..open + 1 + len];
        out.push_str(&rest[..=open]);
        out.push_str(&echo(inner));
        out.push_str(quote);
        rest = &rest[open + 2 + len..];
    }
    out.push_str(rest);
    if out.chars().count() > 8 * crate::error::ECHO_CHARS {
        let cut = out
            .char_indices()
            .nth(8 * crate::error::ECHO_CHARS)
            .map_or(out.len(), |(i, _)| i);
        out = format!("{}… ({} bytes)", &out[..cut], message.len());
    }
    out
}

/// The line of the dotted key `name` (`response_time.sigma`) under
/// `section`, whether its parts are written as tables or an inline table:
/// the line of the deepest part found.
fn find_dotted_key_line(text: &str, section: &[String], name: &str) -> Option<usize> {
    let parts: Vec<&str> = name.split('.').collect();
    (0..parts.len()).rev().find_map(|i| {
        let mut s = section.to_vec();
        s.extend(parts[..i].iter().map(|p| p.to_string()));
        find_key_line(text, &s, parts[i])
    })
}

fn quoted_after(msg: &str, prefix: &str) -> Option<String> {
    let rest = &msg[msg.find(prefix)? + prefix.len()..];
    Some(rest[..rest.find('`')?].to_string())
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |p| offset - p - 1) + 1;
    (line, column)
}

/// The `[a.b]` section in force at byte `offset`.
fn section_at(text: &str, offset: usize) -> Vec<String> {
    let mut section = Vec::new();
    let mut pos = 0;
    for raw in text.split_inclusive('\n') {
        if pos > offset {
            break;
        }
        if let Some(h) = header_of(raw) {
            section = h;
        }
        pos += raw.len();
    }
    section
}

fn header_of(line: &str) -> Option<Vec<String>> {
    let l = line.trim();
    let inner = l
        .strip_prefix("[[")
        .and_then(|r| r.split("]]").next())
        .or_else(|| l.strip_prefix('[').and_then(|r| r.split(']').next()))?;
    Some(
        inner
            .split('.')
            .map(|s| s.trim().trim_matches('"').to_string())
            .collect(),
    )
}

fn key_of(line: &str) -> Option<String> {
    let l = line.trim_start();
    if l.starts_with('#') || l.starts_with('[') {
        return None;
    }
    let eq = l.find('=')?;
    let key = l[..eq].trim().trim_matches('"');
    (!key.is_empty()).then(|| key.to_string())
}

fn key_on_line(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let start = text[..offset].rfind('\n').map_or(0, |p| p + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |p| offset + p);
    key_of(&text[start..end])
}

fn find_key_line(text: &str, section: &[String], key: &str) -> Option<usize> {
    let mut current: Vec<String> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        if let Some(h) = header_of(raw) {
            current = h;
            continue;
        }
        if current == section && key_of(raw).as_deref() == Some(key) {
            return Some(i + 1);
        }
    }
    None
}

/// The literal a serde "invalid type/value" message quotes, as it would be
/// written in TOML: `string "two"` gives `"two"`, `integer `5`` gives `5`.
fn offending_literal(msg: &str) -> Option<String> {
    // An unknown component type: the literal is the `type` value.
    if let Some(r) = msg.strip_prefix("unknown variant `") {
        return Some(format!("\"{}\"", &r[..r.find('`')?]));
    }
    let rest = msg
        .strip_prefix("invalid type: ")
        .or_else(|| msg.strip_prefix("invalid value: "))?;
    if let Some(r) = rest.strip_prefix("string \"") {
        return Some(format!("\"{}\"", &r[..r.find('"')?]));
    }
    let start = rest.find('`')? + 1;
    let end = start + rest[start..].find('`')?;
    Some(rest[start..end].to_string())
}

fn find_value_line(text: &str, section: &[String], literal: &str) -> Option<(usize, String)> {
    let mut current: Vec<String> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        if let Some(h) = header_of(raw) {
            current = h;
            continue;
        }
        if current != section {
            continue;
        }
        let Some(key) = key_of(raw) else { continue };
        let value = raw[raw.find('=')? + 1..]
            .split('#')
            .next()
            .unwrap_or("")
            .trim();
        let normalised = value.replace('\'', "\"");
        if value == literal || normalised == literal || same_number(value, literal) {
            return Some((i + 1, key));
        }
    }
    None
}

/// Whether two number literals have the same value (`1e12` written,
/// `1000000000000.0` quoted by serde).
fn same_number(written: &str, quoted: &str) -> bool {
    let number = |s: &str| s.replace('_', "").parse::<f64>().ok();
    matches!((number(written), number(quoted)), (Some(a), Some(b)) if a == b)
}

fn find_header_line(text: &str, section: &[&str]) -> Option<usize> {
    text.lines()
        .position(|raw| {
            header_of(raw).is_some_and(|h| h.iter().map(String::as_str).eq(section.iter().copied()))
        })
        .map(|i| i + 1)
}

fn join_path(section: &[String], key: &str) -> String {
    if section.is_empty() {
        key.to_string()
    } else {
        format!("{}.{key}", section.join("."))
    }
}
