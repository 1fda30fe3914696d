//! `kinova_feeding` in a build without the `physics` feature: the config
//! type stays known, so a config naming it is read (any keys), and building
//! it fails with [`HilError::Unsupported`] saying how to enable MuJoCo,
//! instead of an "unknown type" error that hides the cause.

use hil_config::{BuildContext, EnvironmentConfig};
use hil_core::{Environment, HilError, Result};
use serde::{Deserialize, Serialize};

/// The `kinova_feeding` table of a config, kept as given.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct KinovaFeedingConfig {
    #[serde(flatten)]
    given: serde_json::Map<String, serde_json::Value>,
}

#[typetag::serde(name = "kinova_feeding")]
impl EnvironmentConfig for KinovaFeedingConfig {
    fn build(&self, _: &BuildContext) -> Result<Box<dyn Environment>> {
        Err(HilError::unsupported(
            "this build",
            "the `kinova_feeding` environment",
            crate::ENABLE_PHYSICS,
        ))
    }
}
