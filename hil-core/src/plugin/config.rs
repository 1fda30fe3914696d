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
/// registered its `type`, else whatever typetag knows. Use it as
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
        && registry::is_registered(T::KIND, name)
    {
        let mut params = match value {
            toml::Value::Table(t) => t,
            _ => unreachable!("only tables have a `type` key"),
        };
        let name = name_of(&mut params);
        return Ok(T::from_plugin(PluginComponent { name, params }));
    }
    Box::<T>::deserialize(value).map_err(|e| {
        let msg = e.message().trim().to_string();
        match (msg.strip_prefix("unknown variant `"), ty.as_deref()) {
            (Some(_), Some(name)) => {
                let mut known = builtin_names(T::KIND);
                known.extend(registry::components(T::KIND).into_iter().map(|c| c.name));
                D::Error::custom(format!(
                    "unknown variant `{name}`: {}",
                    registry::unknown_message(T::KIND, name, &known)
                ))
            }
            _ => D::Error::custom(msg),
        }
    })
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

/// The names in serde's "expected one of `a`, `b`" (or "expected `a`").
fn variants_of(msg: &str) -> Vec<String> {
    let Some(i) = msg.find("expected ") else {
        return Vec::new();
    };
    msg[i..]
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

fn try_builtin(kind: ComponentKind, name: &str) -> std::result::Result<(), String> {
    let mut t = toml::Table::new();
    t.insert("type".into(), toml::Value::String(name.to_string()));
    let v = toml::Value::Table(t);
    let r = match kind {
        ComponentKind::Policy => Box::<dyn PolicyConfig>::deserialize(v).map(drop),
        ComponentKind::Environment => Box::<dyn EnvironmentConfig>::deserialize(v).map(drop),
        ComponentKind::WorkloadModel => Box::<dyn WorkloadModelConfig>::deserialize(v).map(drop),
        ComponentKind::QueryChannel => Box::<dyn QueryChannelConfig>::deserialize(v).map(drop),
    };
    r.map_err(|e| e.message().to_string())
}

/// Whether typetag knows a built-in type `name` of `kind`.
pub(crate) fn builtin_knows(kind: ComponentKind, name: &str) -> bool {
    match try_builtin(kind, name) {
        Ok(()) => true,
        Err(msg) => !msg.starts_with("unknown variant"),
    }
}

/// The built-in (typetag) type names of `kind`.
pub(crate) fn builtin_names(kind: ComponentKind) -> Vec<String> {
    // Ask typetag about a name nobody registers: its error lists them all.
    match try_builtin(kind, "\u{0}") {
        Ok(()) => Vec::new(),
        // `plugin` is the explicit form, not a type worth suggesting.
        Err(msg) => variants_of(&msg)
            .into_iter()
            .filter(|n| n != "plugin")
            .collect(),
    }
}
