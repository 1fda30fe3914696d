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
//! The component fields of `hil_experiments::ExperimentConfig` deserialise through
//! [`component`]: a `type` that a loaded plugin registered becomes a
//! [`PluginComponent`] (its other keys become the factory's TOML
//! parameters); any other `type` goes to typetag as before, and an unknown
//! one gets an error listing the closest built-in and plugin names. The
//! explicit form `type = "plugin"`, `name = "..."`, `params = {...}` is what
//! a [`PluginComponent`] serialises to.

use std::marker::PhantomData;
use std::sync::Arc;

use serde::de::value::{BorrowedStrDeserializer, MapAccessDeserializer, StringDeserializer};
use serde::de::{DeserializeOwned, DeserializeSeed, Error as _, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::builtin::{builtin_knows, builtin_types};
use super::registrar::{ComponentKind, Params};
use super::registry;
use hil_config::TaskContext;
use hil_config::{
    BuildContext, EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig,
};
use hil_core::error::{HilError, Result};
use hil_core::{Environment, Policy, QueryChannel, WorkloadModel};

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
/// `#[serde(deserialize_with = "hil_plugin::component")]` on a
/// `Box<dyn PolicyConfig>` (or any of the four) field of a config file of
/// your own, so that plugin types work there as in `hil_experiments::ExperimentConfig`.
pub fn component<'de, D, T>(d: D) -> std::result::Result<Box<T>, D::Error>
where
    D: Deserializer<'de>,
    T: KindOf + ?Sized,
    Box<T>: DeserializeOwned,
{
    d.deserialize_map(ComponentVisitor::<T>(PhantomData))
}

/// Reads a component table. When `type` is its first key (as configs write
/// it), the rest of the table streams into the chosen type, so an error
/// inside it keeps the parser's location; otherwise the table is read whole
/// first.
struct ComponentVisitor<T: ?Sized>(PhantomData<fn() -> Box<T>>);

impl<'de, T> Visitor<'de> for ComponentVisitor<T>
where
    T: KindOf + ?Sized,
    Box<T>: DeserializeOwned,
{
    type Value = Box<T>;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a {} table with a `type` key", T::KIND)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<Box<T>, A::Error> {
        let first = map.next_key::<String>()?;
        if first.as_deref() == Some("type") {
            let name = map.next_value_seed(TypeName(T::KIND))?;
            if name != "plugin" && registry::is_registered(T::KIND, &name) {
                let mut params = toml::Table::new();
                while let Some(key) = map.next_key::<String>()? {
                    params.insert(key, map.next_value()?);
                }
                return Ok(T::from_plugin(PluginComponent { name, params }));
            }
            return Box::<T>::deserialize(MapAccessDeserializer::new(TypeFirst {
                name: Some(name),
                key_given: false,
                rest: map,
            }));
        }
        let mut table = toml::Table::new();
        if let Some(key) = first {
            table.insert(key, map.next_value()?);
            while let Some(key) = map.next_key::<String>()? {
                table.insert(key, map.next_value()?);
            }
        }
        from_table::<T, A::Error>(table)
    }
}

/// A component table whose `type` is not its first key: decided on the
/// whole table.
fn from_table<T, E>(mut table: toml::Table) -> std::result::Result<Box<T>, E>
where
    T: KindOf + ?Sized,
    Box<T>: DeserializeOwned,
    E: serde::de::Error,
{
    if let Some(toml::Value::String(name)) = table.get("type")
        && name != "plugin"
    {
        if registry::is_registered(T::KIND, name) {
            let name = name_of(&mut table);
            return Ok(T::from_plugin(PluginComponent {
                name,
                params: table,
            }));
        }
        if !builtin_knows(T::KIND, name) {
            return Err(E::custom(unknown_type(T::KIND, name)));
        }
    }
    Box::<T>::deserialize(toml::Value::Table(table)).map_err(|e| E::custom(e.message().trim()))
}

/// The error for a `type` no built-in type and no plugin has.
fn unknown_type(kind: ComponentKind, name: &str) -> String {
    let mut known = builtin_types(kind);
    known.extend(registry::components(kind).into_iter().map(|c| c.name));
    format!(
        "unknown variant `{name}`: {}",
        registry::unknown_message(kind, name, &known)
    )
}

/// Reads a `type` value, refusing a name nobody registered (so the error
/// sits at the value).
struct TypeName(ComponentKind);

impl<'de> DeserializeSeed<'de> for TypeName {
    type Value = String;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> std::result::Result<String, D::Error> {
        let name = String::deserialize(d)?;
        if name != "plugin"
            && !registry::is_registered(self.0, &name)
            && !builtin_knows(self.0, &name)
        {
            return Err(D::Error::custom(unknown_type(self.0, &name)));
        }
        Ok(name)
    }
}

/// The rest of a component table after its `type`, with the `type` handed
/// out again first, so that typetag reads it without buffering the table.
struct TypeFirst<A> {
    name: Option<String>,
    key_given: bool,
    rest: A,
}

impl<'de, A: MapAccess<'de>> MapAccess<'de> for TypeFirst<A> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> std::result::Result<Option<K::Value>, A::Error> {
        if self.name.is_some() && !self.key_given {
            self.key_given = true;
            return seed
                .deserialize(BorrowedStrDeserializer::<A::Error>::new("type"))
                .map(Some);
        }
        self.rest.next_key_seed(seed)
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(
        &mut self,
        seed: V,
    ) -> std::result::Result<V::Value, A::Error> {
        match self.name.take() {
            Some(name) => seed.deserialize(StringDeserializer::<A::Error>::new(name)),
            None => self.rest.next_value_seed(seed),
        }
    }
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
