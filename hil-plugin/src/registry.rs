//! The host's registry of plugin factories: one per process, filled by
//! [`super::load`] (or [`register_static`]) and read by configs and the CLI.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{LazyLock, Mutex, RwLock};

use super::abi::BuildFacts;
use super::registrar::{ComponentKind, Factory, Params, PluginRegistrar, Registrar};
use hil_config::{BuildContext, TaskContext};
use hil_core::error::{HilError, Result};
use hil_core::{Environment, Policy, QueryChannel, WorkloadModel};

/// One registered component type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ComponentInfo {
    /// What it builds.
    pub kind: ComponentKind,
    /// The name configs use (`type = "<name>"`).
    pub name: String,
    /// One line saying what it is.
    pub description: String,
    /// The library that registered it.
    pub library: PathBuf,
}

/// A loaded plugin library and what it declared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PluginInfo {
    /// The library's canonical path (or the label of a static registration).
    pub path: PathBuf,
    /// The plugin's ABI version.
    pub abi_version: u32,
    /// `(fact, value)` pairs: hil-core version, rustc version, target, profile.
    pub build: Vec<(String, String)>,
    /// The types it registered, in registration order.
    pub components: Vec<ComponentInfo>,
}

struct Entry {
    info: ComponentInfo,
    factory: Factory,
}

#[derive(Default)]
struct Registry {
    libraries: Vec<PluginInfo>,
    entries: BTreeMap<(ComponentKind, String), Entry>,
}

static REGISTRY: LazyLock<RwLock<Registry>> = LazyLock::new(Default::default);

/// Serialises whole loads, so one library is never registered twice by two
/// threads racing.
pub(crate) static LOAD_LOCK: Mutex<()> = Mutex::new(());

fn read() -> std::sync::RwLockReadGuard<'static, Registry> {
    // A panic while holding the lock cannot leave the maps half-updated
    // (commits insert only after every check), so poisoning is harmless.
    REGISTRY.read().unwrap_or_else(|e| e.into_inner())
}

fn write() -> std::sync::RwLockWriteGuard<'static, Registry> {
    REGISTRY.write().unwrap_or_else(|e| e.into_inner())
}

/// The library already loaded from `path` (canonical), if any.
pub(crate) fn loaded(path: &Path) -> Option<PluginInfo> {
    read().libraries.iter().find(|l| l.path == path).cloned()
}

/// Every library loaded so far.
pub fn libraries() -> Vec<PluginInfo> {
    read().libraries.clone()
}

/// Every registered type of `kind`, sorted by name.
pub fn components(kind: ComponentKind) -> Vec<ComponentInfo> {
    read()
        .entries
        .values()
        .filter(|e| e.info.kind == kind)
        .map(|e| e.info.clone())
        .collect()
}

/// Whether a plugin registered a type `name` of `kind`.
pub fn is_registered(kind: ComponentKind, name: &str) -> bool {
    read().entries.contains_key(&(kind, name.to_string()))
}

/// Up to three of `candidates` closest to `name`, closest first.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let mut scored: Vec<(f64, &str)> = candidates
        .into_iter()
        .map(|c| (strsim::normalized_damerau_levenshtein(name, c), c))
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(b.1)));
    scored.dedup_by(|a, b| a.1 == b.1);
    scored
        .into_iter()
        .take(3)
        .map(|(_, c)| c.to_string())
        .collect()
}

/// The message for a name nobody registered, with the closest known names.
pub(crate) fn unknown_message(kind: ComponentKind, name: &str, known: &[String]) -> String {
    let close = closest(name, known.iter().map(String::as_str));
    if close.is_empty() {
        format!(
            "no {kind} type `{name}` is built in or registered by a loaded plugin, and none are known"
        )
    } else {
        format!(
            "no {kind} type `{name}` is built in or registered by a loaded plugin; closest: {}",
            close
                .iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

fn factory(kind: ComponentKind, name: &str) -> Result<(Factory, PathBuf)> {
    let reg = read();
    match reg.entries.get(&(kind, name.to_string())) {
        Some(e) => Ok((e.factory.clone(), e.info.library.clone())),
        None => {
            let mut known: Vec<String> = reg
                .entries
                .keys()
                .filter(|(k, _)| *k == kind)
                .map(|(_, n)| n.clone())
                .collect();
            known.extend(super::builtin::builtin_types(kind));
            Err(HilError::invalid_parameter(
                "type",
                name,
                unknown_message(kind, name, &known),
            ))
        }
    }
}

/// Says which type rejected what, unless the plugin already said it
/// (a panic is reported as a plugin error by the guard).
fn rejected(kind: ComponentKind, name: &str, library: &Path, e: HilError) -> HilError {
    match e {
        e @ HilError::Plugin { .. } => e,
        e => HilError::Plugin {
            path: library.to_path_buf(),
            why: format!("{kind} `{name}` could not be built from its parameters: {e}"),
        },
    }
}

macro_rules! builder {
    ($(#[$doc:meta])* $fn:ident, $variant:ident, $ctx:ty, $out:ty) => {
        $(#[$doc])*
        pub fn $fn(name: &str, params: &Params, ctx: &$ctx) -> Result<$out> {
            let kind = ComponentKind::$variant;
            let (f, lib) = factory(kind, name)?;
            let Factory::$variant(f) = f else {
                unreachable!("entries are keyed by kind")
            };
            f(params, ctx).map_err(|e| rejected(kind, name, &lib, e))
        }
    };
}

builder!(
    /// Builds the plugin policy registered as `name`.
    build_policy, Policy, TaskContext, Box<dyn Policy>
);
builder!(
    /// Builds the plugin environment registered as `name`.
    build_environment, Environment, BuildContext, Box<dyn Environment>
);
builder!(
    /// Builds the plugin workload model registered as `name`.
    build_workload_model, WorkloadModel, BuildContext, Box<dyn WorkloadModel>
);
builder!(
    /// Builds the plugin query channel registered as `name`.
    build_query_channel, QueryChannel, TaskContext, Box<dyn QueryChannel>
);

/// Collects a library's registrations; nothing is committed until the
/// whole registration has been checked.
pub(crate) struct HostRegistrar {
    library: PathBuf,
    pending: Vec<Entry>,
}

impl HostRegistrar {
    pub(crate) fn new(library: PathBuf) -> Self {
        Self {
            library,
            pending: Vec::new(),
        }
    }

    /// Checks every registration and commits them all, or none.
    pub(crate) fn commit(self, abi_version: u32, build: &BuildFacts) -> Result<PluginInfo> {
        let mut problems = Vec::new();
        let mut reg = write();
        for (i, e) in self.pending.iter().enumerate() {
            let (kind, name) = (e.info.kind, e.info.name.as_str());
            if name.is_empty() || name.chars().any(|c| c.is_whitespace() || c == '"') {
                problems.push(format!(
                    "{kind} name `{name}` is invalid: names are non-empty, without spaces or quotes"
                ));
            } else if let Some(other) = reg.entries.get(&(kind, name.to_string())) {
                problems.push(format!(
                    "duplicate {kind} name `{name}`: already registered by {}",
                    other.info.library.display()
                ));
            } else if self.pending[..i]
                .iter()
                .any(|p| p.info.kind == kind && p.info.name == name)
            {
                problems.push(format!(
                    "duplicate {kind} name `{name}`: registered twice by this library"
                ));
            } else if super::builtin::builtin_knows(kind, name) {
                problems.push(format!(
                    "duplicate {kind} name `{name}`: a built-in type already has it"
                ));
            }
        }
        if !problems.is_empty() {
            return Err(HilError::Plugin {
                path: self.library,
                why: problems.join("; "),
            });
        }
        let info = PluginInfo {
            path: self.library.clone(),
            abi_version,
            build: build
                .fields()
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            components: self.pending.iter().map(|e| e.info.clone()).collect(),
        };
        for e in self.pending {
            reg.entries.insert((e.info.kind, e.info.name.clone()), e);
        }
        reg.libraries.push(info.clone());
        Ok(info)
    }
}

impl PluginRegistrar for HostRegistrar {
    fn library(&self) -> &Path {
        &self.library
    }
    fn add(&mut self, name: &str, description: &str, factory: Factory) {
        self.pending.push(Entry {
            info: ComponentInfo {
                kind: factory.kind(),
                name: name.to_string(),
                description: description.to_string(),
                library: self.library.clone(),
            },
            factory,
        });
    }
}

/// Registers factories compiled into this program, under the label
/// `label`, exactly as a loaded plugin would (same guards, same name
/// checks). Useful to test a plugin crate without loading it, and for
/// programs that bundle extra types. Registering the same label twice is
/// harmless: the second call returns the first registration.
///
/// ```
/// use std::path::Path;
/// use hil_plugin::{self as plugin, ComponentKind, Params};
/// use hil_conformance::fixtures::CountingWorkload;
/// use hil_core::{QueryHistory, WorkloadInput};
/// use hil_config::BuildContext;
///
/// plugin::register_static(Path::new("doc-example"), |r| {
///     r.workload_model("doc_counting", "a step per query", |_p, _ctx| {
///         Ok(Box::new(CountingWorkload::new(0.1)))
///     });
/// })
/// .unwrap();
/// assert!(plugin::is_registered(ComponentKind::WorkloadModel, "doc_counting"));
/// let m = plugin::build_workload_model("doc_counting", &Params::empty(), &BuildContext::new(".", 0)).unwrap();
/// assert_eq!(m.predict(&WorkloadInput::new(0.5, &QueryHistory::new(), 0)).unwrap(), 0.5);
/// let e = plugin::build_workload_model("doc_countin", &Params::empty(), &BuildContext::new(".", 0));
/// assert!(e.err().unwrap().to_string().contains("closest: `doc_counting`"));
/// ```
pub fn register_static(
    label: &Path,
    register: impl FnOnce(&mut Registrar<'_>),
) -> Result<PluginInfo> {
    let _load = LOAD_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(info) = loaded(label) {
        return Ok(info);
    }
    let mut host = HostRegistrar::new(label.to_path_buf());
    super::registrar::run_register(&mut host, register).map_err(|msg| HilError::Plugin {
        path: label.to_path_buf(),
        why: format!("registration panicked: {msg}"),
    })?;
    host.commit(super::abi::ABI_VERSION, &BuildFacts::current())
}
