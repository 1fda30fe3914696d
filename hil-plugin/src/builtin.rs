//! The built-in (typetag) component types this program holds: asked of
//! typetag itself, so the names are those of every crate linked in.

use serde::Deserialize;

use hil_config::{EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig};

use crate::registrar::ComponentKind;

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
/// use hil_plugin::{ComponentKind, builtin_types};
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
