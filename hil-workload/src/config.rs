//! Config types: name a workload model in an experiment TOML.
//!
//! ```toml
//! [workload]
//! type = "bundled"
//! name = "f1_sim"
//! ```
//! or
//! ```toml
//! [workload]
//! type = "model_file"
//! path = "models/my_model.json"   # relative to the config file
//! ```

use std::path::PathBuf;
use std::sync::Arc;

use hil_config::BuildContext;
use hil_config::WorkloadModelConfig;
use hil_core::{Result, WorkloadModel};
use serde::{Deserialize, Serialize};

/// A model shipped with hil-workload (see [`crate::bundled`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BundledModelConfig {
    /// `f1_sim`, `f2_sim`, `f12_sim`, `f1_real` or `f12_real`.
    pub name: String,
}

#[typetag::serde(name = "bundled")]
impl WorkloadModelConfig for BundledModelConfig {
    fn build(&self, _ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>> {
        crate::bundled::load(&self.name)
    }
}

/// A model JSON file written by `hil workload fit` or `bundle`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFileConfig {
    /// Path of the model JSON, relative to the config's directory.
    pub path: PathBuf,
}

#[typetag::serde(name = "model_file")]
impl WorkloadModelConfig for ModelFileConfig {
    fn build(&self, ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>> {
        crate::load_model_json(ctx.resolve(&self.path))
    }
}
