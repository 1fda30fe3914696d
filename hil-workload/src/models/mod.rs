//! The model families (one module each) and the versioned JSON model file.
//!
//! A model file is
//! `{"format": "hil-workload-model", "format_version": 1, "name": ..., "spec": {"family": ..., ...}, "provenance": {...}}`.
//! Loading checks the format and version first, so a file from another
//! version is a clear error rather than a confusing field mismatch.

use hil_core::WorkloadInput;
pub mod average;
pub mod constant;
pub mod exp_impulse;
pub mod granger;
pub(crate) mod impulse_sums;

use std::path::Path;

use hil_core::{HilError, Result, WorkloadModel};
use serde::{Deserialize, Serialize};

pub use average::AverageModel;
pub use constant::ConstantModel;
pub use exp_impulse::ExpImpulseModel;
pub use granger::{GrangerModel, GrangerVariant};

/// The `format` tag of model files.
pub const FORMAT: &str = "hil-workload-model";
/// The model-file version this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// The parameters of one model of any family.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case")]
pub enum ModelSpec {
    /// WL_t = WL_0.
    Constant(ConstantModel),
    /// The training set's mean WL_0.
    Average(AverageModel),
    /// A Granger linear model (any variant).
    Granger(GrangerModel),
    /// Exponential decay with impulses.
    ExpImpulse(ExpImpulseModel),
}

impl ModelSpec {
    /// The model as a trait object.
    pub fn as_model(&self) -> &dyn WorkloadModel {
        match self {
            Self::Constant(m) => m,
            Self::Average(m) => m,
            Self::Granger(m) => m,
            Self::ExpImpulse(m) => m,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        match self {
            Self::Constant(_) => Ok(()),
            Self::Average(m) => m.validate(),
            Self::Granger(m) => m.validate(),
            Self::ExpImpulse(m) => m.validate(),
        }
    }

    /// True if adding a query can never lower the prediction.
    pub fn is_monotone(&self) -> bool {
        match self {
            Self::Constant(_) | Self::Average(_) => true,
            Self::Granger(m) => m.variant.is_monotone(),
            Self::ExpImpulse(m) => m.impulse.iter().all(|b| *b >= 0.0),
        }
    }
}

/// Where a fitted model came from.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// Dataset it was fitted on (`d1`, `d2`, `d12`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dataset: Option<String>,
    /// The study data (file name or description).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Number of training pairs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n_pairs: Option<usize>,
    /// Cross-validated test MSE (mean, std, median), when selected by CV.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cv_test_mse: Option<[f64; 3]>,
    /// Free-text note (e.g. "synthetic data calibrated to the paper").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A named model with provenance: what model files hold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedModel {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`FORMAT_VERSION`] when written by this build.
    pub format_version: u32,
    /// Model name (e.g. `f1_sim`).
    pub name: String,
    /// The parameters.
    pub spec: ModelSpec,
    /// Where it came from.
    #[serde(default)]
    pub provenance: Provenance,
}

impl FittedModel {
    /// Wraps `spec` under `name` with the current format version.
    pub fn new(name: impl Into<String>, spec: ModelSpec, provenance: Provenance) -> Self {
        Self {
            format: FORMAT.into(),
            format_version: FORMAT_VERSION,
            name: name.into(),
            spec,
            provenance,
        }
    }

    /// Serialises to pretty JSON. Floats are written in shortest round-trip
    /// form, so loading gives bit-identical predictions.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("model specs always serialise");
        s.push('\n');
        s
    }

    /// Parses model JSON; `origin` names the source in errors.
    ///
    /// ```
    /// use hil_workload::models::{FittedModel, ModelSpec, ConstantModel, Provenance};
    /// let m = FittedModel::new("c", ModelSpec::Constant(ConstantModel {}), Provenance::default());
    /// let back = FittedModel::from_json(&m.to_json(), "inline".as_ref()).unwrap();
    /// assert_eq!(back, m);
    /// let old = m.to_json().replace("\"format_version\": 1", "\"format_version\": 0");
    /// let err = FittedModel::from_json(&old, "inline".as_ref()).unwrap_err().to_string();
    /// assert!(err.contains("format_version") && err.contains("version 0"));
    /// ```
    pub fn from_json(text: &str, origin: &Path) -> Result<Self> {
        let err = |line: usize, field: &str, why: String| HilError::Data {
            path: origin.to_path_buf(),
            record: line,
            field: field.to_string(),
            why,
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| err(e.line(), "(json)", e.to_string()))?;
        let line_of = |key: &str| {
            text.lines()
                .position(|l| l.contains(&format!("\"{key}\"")))
                .map_or(1, |i| i + 1)
        };
        match value.get("format").and_then(|v| v.as_str()) {
            Some(FORMAT) => {}
            other => {
                return Err(err(
                    line_of("format"),
                    "format",
                    format!(
                        "expected \"{FORMAT}\", found {other:?}: not a hil workload model file"
                    ),
                ));
            }
        }
        match value.get("format_version").and_then(|v| v.as_u64()) {
            Some(v) if v == u64::from(FORMAT_VERSION) => {}
            Some(v) => {
                return Err(err(
                    line_of("format_version"),
                    "format_version",
                    format!(
                        "the file has format version {v}; this build reads version {FORMAT_VERSION} only (refit or convert the model)"
                    ),
                ));
            }
            None => {
                return Err(err(
                    line_of("format_version"),
                    "format_version",
                    "missing or not an unsigned integer".into(),
                ));
            }
        }
        let m: Self =
            serde_json::from_str(text).map_err(|e| err(e.line(), "spec", e.to_string()))?;
        m.spec
            .validate()
            .map_err(|e| err(line_of("spec"), "spec", e.to_string()))?;
        Ok(m)
    }

    /// Reads a model file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = hil_core::files::read_text(path, hil_core::files::limits::MODEL)?;
        Self::from_json(&text, path)
    }

    /// Writes a model file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        std::fs::write(path, self.to_json()).map_err(|e| HilError::io("writing", path, e))
    }
}

impl WorkloadModel for FittedModel {
    fn name(&self) -> &str {
        &self.name
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        self.spec.as_model().predict(input)
    }
}
