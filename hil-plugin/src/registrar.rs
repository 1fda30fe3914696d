//! How a plugin hands its factories to the host.
//!
//! The host implements [`PluginRegistrar`]; the plugin only ever sees it
//! through [`Registrar`], whose methods wrap every factory and every object a
//! factory returns in the panic guards of [`super::guard`]. Those wrappers
//! are generic over the plugin's closures, so they are compiled into the
//! plugin, on the plugin's side of the boundary, with the plugin's copy of
//! the standard library: a panic is caught where it can be caught.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::de::DeserializeOwned;

use super::guard::{
    self, DropPanicSink, GuardedChannel, GuardedEnvironment, GuardedPolicy, GuardedWorkload,
};
use hil_config::{BuildContext, TaskContext};
use hil_core::error::{HilError, Result};
use hil_core::{Environment, Policy, QueryChannel, WorkloadModel};

/// The four kinds of component a plugin can provide.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ComponentKind {
    /// A [`Policy`].
    Policy,
    /// An [`Environment`].
    Environment,
    /// A [`WorkloadModel`].
    WorkloadModel,
    /// A [`QueryChannel`].
    QueryChannel,
}

impl ComponentKind {
    /// All kinds.
    pub const ALL: [Self; 4] = [
        Self::Policy,
        Self::Environment,
        Self::WorkloadModel,
        Self::QueryChannel,
    ];

    /// Lower-case name, as in messages and `hil plugins list`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Policy => "policy",
            Self::Environment => "environment",
            Self::WorkloadModel => "workload model",
            Self::QueryChannel => "query channel",
        }
    }
}

impl std::fmt::Display for ComponentKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The format of a [`Params`] text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamFormat {
    /// A TOML table (the body of a config section).
    Toml,
    /// A JSON object.
    Json,
}

/// A factory's parameters: a TOML or JSON text. Plain text crosses the
/// plugin boundary where typetag's registry cannot.
///
/// ```
/// use hil_plugin::Params;
/// #[derive(serde::Deserialize)]
/// struct P { alpha: f64 }
/// let p: P = Params::toml("alpha = 0.5").parse("my_policy").unwrap();
/// assert_eq!(p.alpha, 0.5);
/// let p: P = Params::json(r#"{"alpha": 2.0}"#).parse("my_policy").unwrap();
/// assert_eq!(p.alpha, 2.0);
/// assert!(Params::json("{}").parse::<P>("my_policy").is_err());
/// // Several keys on one line are not TOML; the error points to the JSON form.
/// let r = Params::toml("alpha = 0.5, beta = 1").parse::<P>("my_policy");
/// assert!(matches!(r, Err(hil_core::HilError::Serde { .. })));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Params {
    text: String,
    format: ParamFormat,
}

impl Params {
    /// TOML parameters (an empty text is an empty table).
    pub fn toml(text: impl Into<String>) -> Self {
        Self {
            text: text.into(),
            format: ParamFormat::Toml,
        }
    }

    /// JSON parameters (an empty text is an empty object).
    pub fn json(text: impl Into<String>) -> Self {
        Self {
            text: text.into(),
            format: ParamFormat::Json,
        }
    }

    /// No parameters: an empty table.
    pub fn empty() -> Self {
        Self::toml("")
    }

    /// The raw text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The format of the text.
    pub fn format(&self) -> ParamFormat {
        self.format
    }

    /// Deserialises the parameters of the type registered as `type_name`.
    /// Errors name the type and say what is wrong (unknown or missing field,
    /// bad value), as a [`HilError::Serde`].
    pub fn parse<T: DeserializeOwned>(&self, type_name: &str) -> Result<T> {
        let what = || format!("parameters of `{type_name}`");
        match self.format {
            ParamFormat::Toml => {
                toml::from_str(&self.text).map_err(|e| {
                    let mut why = e.message().trim().to_string();
                    if one_line_of_several_keys(&self.text) {
                        why.push_str(
                            "; several keys on one line are not TOML: give them as JSON instead (`{\"a\": 1, \"b\": 2}`), or one `key = value` per line",
                        );
                    }
                    HilError::serde(what(), why)
                })
            }
            ParamFormat::Json => {
                let text = if self.text.trim().is_empty() {
                    "{}"
                } else {
                    &self.text
                };
                serde_json::from_str(text).map_err(|e| HilError::serde(what(), e))
            }
        }
    }
}

/// Whether a TOML text that failed to parse looks like several `key = value`
/// pairs written on one line (`a = 1, b = 2`), as a command line invites.
fn one_line_of_several_keys(text: &str) -> bool {
    text.lines()
        .any(|l| l.matches('=').count() > 1 && !l.trim_start().starts_with('['))
}

/// Builds a policy from parameters and the experiment's build context.
pub type PolicyFactory = FactoryOf<dyn Policy, TaskContext>;
/// Builds an environment.
pub type EnvironmentFactory = FactoryOf<dyn Environment>;
/// Builds a workload model.
pub type WorkloadModelFactory = FactoryOf<dyn WorkloadModel>;
/// Builds a query channel.
pub type QueryChannelFactory = FactoryOf<dyn QueryChannel, TaskContext>;
/// Builds a component of type `T` from its parameters and a context `C`
/// ([`BuildContext`] for environments and workload models, [`TaskContext`]
/// for policies and query channels).
pub type FactoryOf<T, C = BuildContext> = Arc<dyn Fn(&Params, &C) -> Result<Box<T>> + Send + Sync>;

/// A factory of any kind.
#[derive(Clone)]
pub enum Factory {
    /// Builds policies.
    Policy(PolicyFactory),
    /// Builds environments.
    Environment(EnvironmentFactory),
    /// Builds workload models.
    WorkloadModel(WorkloadModelFactory),
    /// Builds query channels.
    QueryChannel(QueryChannelFactory),
}

impl Factory {
    /// The kind of component it builds.
    pub fn kind(&self) -> ComponentKind {
        match self {
            Self::Policy(_) => ComponentKind::Policy,
            Self::Environment(_) => ComponentKind::Environment,
            Self::WorkloadModel(_) => ComponentKind::WorkloadModel,
            Self::QueryChannel(_) => ComponentKind::QueryChannel,
        }
    }
}

impl std::fmt::Debug for Factory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Factory({})", self.kind())
    }
}

/// The host's side of registration. Implemented by the host; plugins use
/// [`Registrar`], which guards what it passes on.
pub trait PluginRegistrar {
    /// The library being registered (for messages).
    fn library(&self) -> &Path;

    /// Adds a named factory. Problems (a duplicate or invalid name) are
    /// collected by the host and refuse the whole library after `register`.
    fn add(&mut self, name: &str, description: &str, factory: Factory);

    /// Where the plugin's objects report a panic in their destructor. The
    /// default is the host's own [`guard::report_drop_panic`] (this method
    /// is compiled into the host, so the function is the host's), which
    /// [`super::take_destructor_panics`] reads.
    fn drop_panic_sink(&self) -> DropPanicSink {
        guard::report_drop_panic
    }
}

/// What a plugin's registration function receives: registers named,
/// panic-guarded factories for any of the four traits.
///
/// ```
/// use hil_plugin::{Params, Registrar};
/// use hil_conformance::fixtures::CountingWorkload;
/// fn register(r: &mut Registrar<'_>) {
///     r.workload_model("counting_demo", "WL_0 plus a fixed step per query", |p: &Params, _ctx| {
///         #[derive(serde::Deserialize)]
///         struct P { step: f64 }
///         let p: P = p.parse("counting_demo")?;
///         Ok(Box::new(CountingWorkload::new(p.step)))
///     });
/// }
/// # let _ = register;
/// ```
pub struct Registrar<'a> {
    host: &'a mut dyn PluginRegistrar,
    library: PathBuf,
    drop_sink: DropPanicSink,
}

impl std::fmt::Debug for Registrar<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Registrar")
            .field("library", &self.library)
            .finish_non_exhaustive()
    }
}

impl<'a> Registrar<'a> {
    /// Wraps the host's registrar.
    pub fn new(host: &'a mut dyn PluginRegistrar) -> Self {
        let library = host.library().to_path_buf();
        let drop_sink = host.drop_panic_sink();
        Self {
            host,
            library,
            drop_sink,
        }
    }

    /// Registers a policy factory under `name`.
    pub fn policy<F>(&mut self, name: &str, description: &str, factory: F)
    where
        F: Fn(&Params, &TaskContext) -> Result<Box<dyn Policy>> + Send + Sync + 'static,
    {
        let guard = |inner, lib, n: &str, sink| {
            Ok(
                Box::new(GuardedPolicy::new(inner, lib, n)?.reporting_drop_panics_to(sink))
                    as Box<dyn Policy>,
            )
        };
        self.add(name, description, factory, guard, Factory::Policy);
    }

    /// Registers an environment factory under `name`.
    pub fn environment<F>(&mut self, name: &str, description: &str, factory: F)
    where
        F: Fn(&Params, &BuildContext) -> Result<Box<dyn Environment>> + Send + Sync + 'static,
    {
        let guard = |inner, lib, n: &str, sink| {
            Ok(
                Box::new(GuardedEnvironment::new(inner, lib, n)?.reporting_drop_panics_to(sink))
                    as Box<dyn Environment>,
            )
        };
        self.add(name, description, factory, guard, Factory::Environment);
    }

    /// Registers a workload-model factory under `name`.
    pub fn workload_model<F>(&mut self, name: &str, description: &str, factory: F)
    where
        F: Fn(&Params, &BuildContext) -> Result<Box<dyn WorkloadModel>> + Send + Sync + 'static,
    {
        let guard = |inner, lib, n: &str, sink| {
            Ok(
                Box::new(GuardedWorkload::new(inner, lib, n)?.reporting_drop_panics_to(sink))
                    as Box<dyn WorkloadModel>,
            )
        };
        self.add(name, description, factory, guard, Factory::WorkloadModel);
    }

    /// Registers a query-channel factory under `name`.
    pub fn query_channel<F>(&mut self, name: &str, description: &str, factory: F)
    where
        F: Fn(&Params, &TaskContext) -> Result<Box<dyn QueryChannel>> + Send + Sync + 'static,
    {
        let guard = |inner, lib, n: &str, sink| {
            Ok(
                Box::new(GuardedChannel::new(inner, lib, n)?.reporting_drop_panics_to(sink))
                    as Box<dyn QueryChannel>,
            )
        };
        self.add(name, description, factory, guard, Factory::QueryChannel);
    }

    /// The one registration path of every kind: the plugin's factory runs
    /// under the panic guard, and what it builds is wrapped by `guard` (so
    /// every later call into the object is guarded too) before the host
    /// gets it.
    fn add<T: ?Sized + 'static, C: 'static>(
        &mut self,
        name: &str,
        description: &str,
        factory: impl Fn(&Params, &C) -> Result<Box<T>> + Send + Sync + 'static,
        guard: GuardFn<T>,
        kind: fn(FactoryOf<T, C>) -> Factory,
    ) {
        let (lib, n, sink) = (self.library.clone(), name.to_string(), self.drop_sink);
        let f = Arc::new(move |p: &Params, ctx: &C| {
            let inner = guard::call(&lib, &n, "factory", || factory(p, ctx))?;
            guard(inner, lib.clone(), &n, sink)
        });
        self.host.add(name, description, kind(f));
    }
}

/// Wraps what a factory built in its panic guard: the object, its library,
/// its registered name, and where a panic in its destructor goes.
type GuardFn<T> = fn(Box<T>, PathBuf, &str, DropPanicSink) -> Result<Box<T>>;

/// Runs a plugin's registration function under a panic guard. Called by the
/// code [`crate::declare_plugin!`] generates, inside the plugin.
#[doc(hidden)]
pub fn run_register(
    host: &mut dyn PluginRegistrar,
    register: impl FnOnce(&mut Registrar<'_>),
) -> std::result::Result<(), String> {
    let mut r = Registrar::new(host);
    guard::catch(|| register(&mut r)).map_err(|p| p.describe())
}
