//! `[channel] type = "speech"` in a `hil` built without the feature
//! `speech`: the speech crate (and its engines) are left out of such a
//! build, so this stand-in takes the channel's place in the config and
//! says how to get it, instead of an unknown-type error.

use std::collections::BTreeMap;

use hil_config::{QueryChannelConfig, TaskContext};
use hil_core::{HilError, QueryChannel, Result};

/// Why a spoken channel cannot be built here, and how to get one.
pub fn error() -> HilError {
    HilError::channel(
        "speech",
        "this hil was built without speech: run scripts/setup-speech, then build hil with \
         `cargo build --release -p hil-cli --features speech` (add `physics` for the Kinova \
         simulation)",
    )
}

/// A speech channel's table, kept as written.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct SpeechUnavailable {
    #[serde(flatten)]
    fields: BTreeMap<String, toml::Value>,
}

#[typetag::serde(name = "speech")]
impl QueryChannelConfig for SpeechUnavailable {
    fn validate(&self) -> Result<()> {
        Err(error())
    }

    fn build(&self, _ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        Err(error())
    }
}
