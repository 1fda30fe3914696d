//! Models shipped with the crate.
//!
//! - `f1_sim`, `f2_sim`, `f12_sim` and their `_mid` and `_steep` variants:
//!   the simulation models (Granger H = 10), *calibrated* to the paper's
//!   published simulation rows, not fitted: the rows leave the trade-off
//!   between the no-query level and the per-query increment open. The
//!   plain names take its lean end and the `_steep` names its other end
//!   (both in the simulation family: γ and every w_i in [0.05, 1],
//!   w_0 ≤ 1); the `_mid` names the model with the most even per-query
//!   response that meets the rows (every weight ≥ 0, no floor; the README
//!   says why). Regenerate with `hil workload calibrate` (derivation:
//!   `hil_experiments::calibrate`).
//! - `f1_real`, `f12_real`: the cross-validation winners on D1 and D12 of
//!   the bundled synthetic study (`data/synthetic_study.csv`, calibrated to
//!   the paper's published figures; not real participant data). Regenerate
//!   with `hil workload bundle` (see the crate README).

use std::sync::Arc;

use hil_core::{HilError, Result, WorkloadModel};

use crate::models::FittedModel;

/// The bundled models fitted from the bundled synthetic study
/// (`hil workload bundle`).
pub const STUDY_FITTED: [&str; 2] = ["f1_real", "f12_real"];

/// The bundled simulation models calibrated to the paper's published rows
/// (`hil workload calibrate`): lean, then middle, then steep.
pub const CALIBRATED: [&str; 9] = [
    "f1_sim",
    "f2_sim",
    "f12_sim",
    "f1_sim_mid",
    "f2_sim_mid",
    "f12_sim_mid",
    "f1_sim_steep",
    "f2_sim_steep",
    "f12_sim_steep",
];

/// Names of the bundled models: [`CALIBRATED`], then [`STUDY_FITTED`].
pub const NAMES: [&str; CALIBRATED.len() + STUDY_FITTED.len()] = {
    let mut out = [""; CALIBRATED.len() + STUDY_FITTED.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = if i < CALIBRATED.len() {
            CALIBRATED[i]
        } else {
            STUDY_FITTED[i - CALIBRATED.len()]
        };
        i += 1;
    }
    out
};

/// The JSON text of a bundled model.
pub fn json(name: &str) -> Option<&'static str> {
    Some(match name {
        "f1_sim" => include_str!("../models/f1_sim.json"),
        "f2_sim" => include_str!("../models/f2_sim.json"),
        "f12_sim" => include_str!("../models/f12_sim.json"),
        "f1_sim_mid" => include_str!("../models/f1_sim_mid.json"),
        "f2_sim_mid" => include_str!("../models/f2_sim_mid.json"),
        "f12_sim_mid" => include_str!("../models/f12_sim_mid.json"),
        "f1_sim_steep" => include_str!("../models/f1_sim_steep.json"),
        "f2_sim_steep" => include_str!("../models/f2_sim_steep.json"),
        "f12_sim_steep" => include_str!("../models/f12_sim_steep.json"),
        "f1_real" => include_str!("../models/f1_real.json"),
        "f12_real" => include_str!("../models/f12_real.json"),
        _ => return None,
    })
}

/// Loads a bundled model with its metadata.
pub fn load_fitted(name: &str) -> Result<FittedModel> {
    let text = json(name).ok_or_else(|| {
        HilError::invalid_parameter(
            "name",
            name,
            format!(
                "no bundled workload model by that name; available: {}",
                NAMES.join(", ")
            ),
        )
    })?;
    FittedModel::from_json(text, format!("<bundled {name}.json>").as_ref())
}

/// Loads a bundled model.
///
/// ```
/// use hil_core::{QueryHistory, QueryKind, WorkloadInput, WorkloadModel};
/// let m = hil_workload::bundled::load("f1_sim").unwrap();
/// let mut h = QueryHistory::new();
/// let before = m.predict(&WorkloadInput::new(0.5, &h, 3)).unwrap();
/// h.push(3, QueryKind::default()).unwrap();
/// assert!(m.predict(&WorkloadInput::new(0.5, &h, 3)).unwrap() >= before);
/// assert!(hil_workload::bundled::load("nope").is_err());
/// ```
pub fn load(name: &str) -> Result<Arc<dyn WorkloadModel>> {
    Ok(Arc::new(load_fitted(name)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_two_groups() {
        let both: Vec<&str> = CALIBRATED.iter().chain(&STUDY_FITTED).copied().collect();
        let mut sorted_names = NAMES.to_vec();
        let mut sorted_both = both.clone();
        sorted_names.sort();
        sorted_both.sort();
        assert_eq!(sorted_names, sorted_both);
        for n in NAMES {
            load_fitted(n).unwrap();
        }
    }
}
