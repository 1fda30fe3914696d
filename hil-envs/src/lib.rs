//! # hil-envs
//!
//! The paper's simulated testbed for human-in-the-loop bite acquisition:
//!
//! - [`dataset`]: the food dataset format (a TOML manifest plus NumPy `.npy`
//!   arrays), its validating loader and writer (the `.npy` codec is
//!   private to it);
//! - [`feeding`]: the feeding task's vocabulary and facts, defined once as
//!   data (actions, placement settings, foods with descriptions, published
//!   per-food success rates), shared by every crate that needs them;
//! - [`rates`]: the parser of the published per-food success rates the
//!   bundled data is calibrated to; [`generate`]: the seeded synthetic
//!   dataset generator;
//! - [`DatasetReplayEnv`]: the dataset-replay [`hil_core::Environment`]
//!   (config type `food_replay`);
//! - [`demo_plate`]: a small plate of foods for trying the channels without
//!   a robot (config type `demo_plate`);
//! - [`split`]: food-level pretrain / validation / test splits.
//!
//! The paper's protocol that runs on this environment, with its tables and
//! figures, is in the `hil-experiments` crate.
//!
//! **The bundled dataset is synthetic**, calibrated to published figures; it
//! is not the paper's data, and results computed from it are not the paper's
//! results.

pub mod dataset;
pub mod demo_plate;
pub mod env;
pub mod feeding;
pub mod generate;
mod npy;
pub mod rates;
pub mod split;
#[cfg(test)]
mod tests;

use std::sync::{Arc, OnceLock};

pub use dataset::{Food, FoodDataset, FoodImage};
pub use demo_plate::{DemoPlate, DemoPlateConfig};
pub use env::{DatasetReplayEnv, FoodReplayConfig, OutcomeMode, PretrainReward};
pub use split::FoodSplit;

static BUNDLED: OnceLock<Arc<FoodDataset>> = OnceLock::new();

/// The bundled synthetic dataset (16 foods × 30 images, d = 2048), generated
/// in memory on first use by [`generate::SyntheticFoods::default`] and shared
/// afterwards. Deterministic: every process gets the same data.
pub fn bundled_dataset() -> hil_core::Result<Arc<FoodDataset>> {
    if let Some(d) = BUNDLED.get() {
        return Ok(d.clone());
    }
    let d = Arc::new(generate::SyntheticFoods::default().generate()?.dataset);
    Ok(BUNDLED.get_or_init(|| d).clone())
}
