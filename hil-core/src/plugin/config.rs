//! Plugin types in experiment configs.
//!
//! A config names a plugin type exactly like a built-in one:
//!
//! ```toml
//! plugins = ["plugins/libgrasp_env.so"]
//!
//! [environment]
//! type = "grasp_choice"   # registered by the plugin
//! n_objects = 12          # everything else is the factory's parameters
//! ```
//!
//! The component fields of [`crate::ExperimentConfig`] deserialise through
//! [`component`]: a `type` that a loaded plugin registered becomes a
//! [`PluginComponent`] (its other keys become the factory's TOML
//! parameters); any other `type` goes to typetag as before, and an unknown
//! one gets an error listing the closest built-in and plugin names. The
//! explicit form `type = "plugin"`, `name = "..."`, `params = {...}` is what
//! a [`PluginComponent`] serialises to.

use std::sync::Arc;

use serde::de::{DeserializeOwned, Error as _};
use serde::{Deserialize, Deserializer, Serialize};

use super::registrar::{ComponentKind, Params};
use super::registry;
use crate::TaskContext;
use crate::config::{
    BuildContext, EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig,
};
use crate::error::{HilError, Result};
use crate::{Environment, Policy, QueryChannel, WorkloadModel};

/// A component built by a plugin factory: its registered name and its
/// parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PluginComponent {
    /// The name the plugin registered.
    pub name: String,
    /// Parameters handed to the factory as a TOML table.
    #[serde(default)]
    pub params: toml::Table,
}

impl PluginComponent {
    fn params(&self) -> Result<Params> {
        toml::to_string(&self.params)
            .map(Params::toml)
            .map_err(|e| HilError::serde(format!("parameters of `{}`", self.name), e))
    }
}

#[typetag::serde(name = "plugin")]
impl PolicyConfig for PluginComponent {
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn Policy>> {
        registry::build_policy(&self.name, &self.params()?, ctx)
    }
}

#[typetag::serde(name = "plugin")]
impl EnvironmentConfig for PluginComponent {
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Environment>> {
        registry::build_environment(&self.name, &self.params()?, ctx)
    }
}

#[typetag::serde(name = "plugin")]
impl WorkloadModelConfig for PluginComponent {
    fn build(&self, ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>> {
        registry::build_workload_model(&self.name, &self.params()?, ctx).map(Arc::from)
    }
}

#[typetag::serde(name = "plugin")]
impl QueryChannelConfig for PluginComponent {
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        registry::build_query_channel(&self.name, &self.params()?, ctx)
    }
}

/// The config trait of each component kind (`dyn PolicyConfig`, ...): lets
/// [`component`] serve all four. Implemented for exactly those four.
pub trait KindOf {
    /// Which kind of component the config trait builds.
    const KIND: ComponentKind;
    /// Wraps a plugin component as a config of this kind.
    fn from_plugin(c: PluginComponent) -> Box<Self>;
}

macro_rules! kind_of {
    ($t:ident, $kind:ident) => {
        impl KindOf for dyn $t {
            const KIND: ComponentKind = ComponentKind::$kind;
            fn from_plugin(c: PluginComponent) -> Box<Self> {
                Box::new(c)
            }
        }
    };
}
kind_of!(PolicyConfig, Policy);
kind_of!(EnvironmentConfig, Environment);
kind_of!(WorkloadModelConfig, WorkloadModel);
kind_of!(QueryChannelConfig, QueryChannel);

/// Deserialises a component table: a plugin type if a loaded plugin
/// registered its `type`, else a built-in (typetag) type, else an error
/// listing the closest built-in and plugin names. Use it as
/// `#[serde(deserialize_with = "hil_core::plugin::component")]` on a
/// `Box<dyn PolicyConfig>` (or any of the four) field of a config file of
/// your own, so that plugin types work there as in [`crate::ExperimentConfig`].
pub fn component<'de, D, T>(d: D) -> std::result::Result<Box<T>, D::Error>
where
    D: Deserializer<'de>,
    T: KindOf + ?Sized,
    Box<T>: DeserializeOwned,
{
    let value = toml::Value::deserialize(d)?;
    let ty = value
        .get("type")
        .and_then(toml::Value::as_str)
        .map(str::to_string);
    if let Some(name) = ty.as_deref()
        && name != "plugin"
    {
        if registry::is_registered(T::KIND, name) {
            let mut params = match value {
                toml::Value::Table(t) => t,
                _ => unreachable!("only tables have a `type` key"),
            };
            let name = name_of(&mut params);
            return Ok(T::from_plugin(PluginComponent { name, params }));
        }
        if !builtin_knows(T::KIND, name) {
            let mut known = builtin_types(T::KIND);
            known.extend(registry::components(T::KIND).into_iter().map(|c| c.name));
            return Err(D::Error::custom(format!(
                "unknown variant `{name}`: {}",
                registry::unknown_message(T::KIND, name, &known)
            )));
        }
    }
    Box::<T>::deserialize(value).map_err(|e| D::Error::custom(e.message().trim()))
}

/// [`component`] for an optional field.
pub fn optional_component<'de, D, T>(d: D) -> std::result::Result<Option<Box<T>>, D::Error>
where
    D: Deserializer<'de>,
    T: KindOf + ?Sized,
    Box<T>: DeserializeOwned,
{
    component::<D, T>(d).map(Some)
}

fn name_of(table: &mut toml::Table) -> String {
    match table.remove("type") {
        Some(toml::Value::String(s)) => s,
        _ => String::new(),
    }
}

/// What typetag answered for a `type` tag, taken from serde's structured
/// error constructors rather than from message text: typetag reports an
/// unknown tag through [`serde::de::Error::unknown_variant`], handing over
/// the names in its own registry.
#[derive(Debug)]
enum Probe {
    /// The tag is not registered; these are the names that are.
    Unknown(&'static [&'static str]),
    /// Anything else (the tag is known; its fields were missing).
    Other,
}

impl std::fmt::Display for Probe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("type probe")
    }
}

impl std::error::Error for Probe {}

impl serde::de::Error for Probe {
    fn custom<M: std::fmt::Display>(_: M) -> Self {
        Self::Other
    }
    fn unknown_variant(_: &str, expected: &'static [&'static str]) -> Self {
        Self::Unknown(expected)
    }
}

/// Deserialises `{ type = name }` as a config of `kind`: `Some(names)` if
/// typetag has no such type, with the names it has.
fn probe(kind: ComponentKind, name: &str) -> Option<&'static [&'static str]> {
    use serde::de::value::MapDeserializer;
    let table = || MapDeserializer::<_, Probe>::new(std::iter::once(("type", name)));
    let r = match kind {
        ComponentKind::Policy => Box::<dyn PolicyConfig>::deserialize(table()).map(drop),
        ComponentKind::Environment => Box::<dyn EnvironmentConfig>::deserialize(table()).map(drop),
        ComponentKind::WorkloadModel => {
            Box::<dyn WorkloadModelConfig>::deserialize(table()).map(drop)
        }
        ComponentKind::QueryChannel => {
            Box::<dyn QueryChannelConfig>::deserialize(table()).map(drop)
        }
    };
    match r {
        Err(Probe::Unknown(names)) => Some(names),
        Ok(()) | Err(Probe::Other) => None,
    }
}

/// Whether a built-in (typetag) type `name` of `kind` is linked into this
/// program.
pub(crate) fn builtin_knows(kind: ComponentKind, name: &str) -> bool {
    probe(kind, name).is_none()
}

/// The built-in (typetag) config type names of `kind` that this program
/// holds, sorted: those of every crate linked into it (see
/// `hil_experiments::builtin`), without the explicit form `plugin`.
///
/// ```
/// use hil_core::plugin::{ComponentKind, builtin_types};
/// // hil-core alone registers no component type of its own.
/// assert!(builtin_types(ComponentKind::Policy).is_empty());
/// ```
pub fn builtin_types(kind: ComponentKind) -> Vec<String> {
    // A name nobody registers: typetag answers with every name it has.
    probe(kind, "\u{0}")
        .unwrap_or_default()
        .iter()
        // `plugin` is the explicit form, not a type worth suggesting.
        .filter(|n| **n != "plugin")
        .map(|n| n.to_string())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typetag_names_come_through_the_structured_probe() {
        // hil-core itself registers only `plugin`, for every kind; were
        // typetag to stop reporting unknown tags through `unknown_variant`,
        // the probe would find no names and call every name known.
        for kind in [
            ComponentKind::Policy,
            ComponentKind::Environment,
            ComponentKind::WorkloadModel,
            ComponentKind::QueryChannel,
        ] {
            assert_eq!(probe(kind, "\u{0}"), Some(&["plugin"][..]), "{kind}");
            assert!(builtin_knows(kind, "plugin"));
            assert!(!builtin_knows(kind, "no_such_type"));
            assert!(builtin_types(kind).is_empty());
        }
    }
}
