//! # hil-workload
//!
//! Querying-workload models learned from NASA-TLX study data (the paper's
//! second contribution): predict how much workload a robot query imposes
//! from the kind of query and the history of earlier ones.
//!
//! - [`tlx`]: the workload score WL = 0.4·mental + 0.2·temporal + 0.4·effort;
//! - [`study`]: the study CSV format and its validating loader;
//! - [`datasets`]: D1 / D2 / D12 training pairs (survey-time rule, WL_0);
//! - [`features`]: Δt = 10 s one-hot lag features;
//! - [`models`]: Constant, Average, Granger (4 variants + simulation),
//!   Exp-Impulse, and the versioned JSON model file;
//! - [`fit`]: exact ridge and box-constrained least squares;
//! - [`select`]: nested cross-validation and the appendix table;
//! - [`rollout`]: a model's workload over a query schedule;
//! - [`stats`]: Mann-Whitney U and Wilcoxon signed-rank tests;
//! - [`synth`]: a synthetic study calibrated to the paper's figures;
//! - [`demo_counting`]: a simple counting model for demos (`demo_counting`);
//! - [`bundled`]: the shipped models (`f1_sim`, …) and [`config`] types.
//!
//! Bundled data and models are synthetic, calibrated to published figures.
//!
//! ```
//! use hil_core::{QueryHistory, QueryKind, WorkloadInput, WorkloadModel};
//! let model = hil_workload::bundled::load("f12_real").unwrap();
//! let mut history = QueryHistory::new();
//! history.push(1, QueryKind::default()).unwrap();
//! let wl = model.predict(&WorkloadInput::new(0.5, &history, 1)).unwrap();
//! assert!((0.0..=1.0).contains(&wl));
//! ```

pub mod bundle;
pub mod bundled;
pub mod config;
pub mod datasets;
pub mod demo_counting;
pub mod features;
pub mod fit;
pub mod models;
pub mod rollout;
pub mod seeds;
pub mod select;
pub mod study;
pub mod synth;
pub mod tlx;

use std::path::Path;
use std::sync::Arc;

use hil_core::{Result, WorkloadModel};

pub use models::{FittedModel, ModelSpec};

/// Loads a model JSON file (any family) as a workload model.
pub fn load_model_json(path: impl AsRef<Path>) -> Result<Arc<dyn WorkloadModel>> {
    Ok(Arc::new(FittedModel::load(path)?))
}
