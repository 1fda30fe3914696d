//! What the robot sees: the [`Item`] in front of it and its [`Context`], the
//! d-dimensional feature vector the policy sees for one observation.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::error::{HilError, Result};

/// A d-dimensional, finite, `f64` context vector.
///
/// Cheap to clone (reference-counted), immutable once built, and guaranteed
/// finite: [`Context::new`] rejects NaN and infinities, so no policy ever has
/// to check again.
///
/// ```
/// use hil_core::Context;
/// let x = Context::new(vec![0.5, -1.0, 2.0]).unwrap();
/// assert_eq!(x.dim(), 3);
/// assert!(Context::new(vec![f64::NAN]).is_err());
/// ```
#[derive(Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Context(Arc<[f64]>);

impl Context {
    /// Builds a context, rejecting empty vectors and non-finite entries.
    pub fn new(values: impl Into<Arc<[f64]>>) -> Result<Self> {
        let values: Arc<[f64]> = values.into();
        if values.is_empty() {
            return Err(HilError::invalid_input(
                "context",
                "it has no entries (dimension 0)",
            ));
        }
        // One pass without an early exit, which the compiler vectorises
        // (this runs on every context crossing from Python); the offending
        // entry is looked for only when there is one.
        let all_finite = values.iter().fold(true, |ok, v| ok & v.is_finite());
        if !all_finite && let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(HilError::invalid_input(
                format!("context[{i}]"),
                format!("{v} is not finite"),
            ));
        }
        Ok(Self(values))
    }

    /// The dimension d.
    pub fn dim(&self) -> usize {
        self.0.len()
    }

    /// The entries.
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// Returns an error unless the dimension is `expected`.
    pub fn check_dim(&self, expected: usize) -> Result<()> {
        if self.dim() == expected {
            Ok(())
        } else {
            Err(HilError::DimensionMismatch {
                expected,
                got: self.dim(),
            })
        }
    }
}

impl std::ops::Deref for Context {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.0
    }
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // A 2048-d context printed in full drowns every log; show the head.
        let head: Vec<_> = self.0.iter().take(4).collect();
        write!(f, "Context(d={}, {:?}", self.dim(), head)?;
        if self.dim() > 4 {
            write!(f, "…")?;
        }
        write!(f, ")")
    }
}

impl<'de> Deserialize<'de> for Context {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        Context::new(v).map_err(serde::de::Error::custom)
    }
}

/// Checks a raw slice the way [`Context::new`] does, without allocating.
pub fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(HilError::invalid_input(
            format!("{what}[{i}]"),
            format!("{} is not finite", values[i]),
        )),
        None => Ok(()),
    }
}

/// One item the robot must handle (a food piece on the plate).
///
/// ```
/// let item = hil_core::Item::new(0, "banana").with_description("on the plate's rim");
/// assert_eq!((item.index, item.label.as_str()), (0, "banana"));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Item {
    /// Position of the item in the episode (0-based).
    pub index: usize,
    /// The item's type (e.g. `banana`).
    pub label: String,
    /// Free-form description a human channel may show.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
}

impl Item {
    /// Item number `index` (0-based) of type `label`.
    pub fn new(index: usize, label: impl Into<String>) -> Self {
        Self {
            index,
            label: label.into(),
            description: None,
        }
    }

    /// With a description a human channel may show.
    pub fn with_description(mut self, description: impl Into<String>) -> Self {
        self.description = Some(description.into());
        self
    }
}
