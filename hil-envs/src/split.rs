//! Splitting a dataset's foods into pretraining, validation and test sets.

use hil_core::{HilError, Result};
use hil_paper::simulation;
use serde::{Deserialize, Serialize};

use crate::dataset::FoodDataset;

/// The foods of each phase of the protocol. Splitting is by food type: no
/// food appears in two sets.
///
/// ```
/// use hil_envs::split::FoodSplit;
/// let ds = hil_envs::bundled_dataset().unwrap();
/// let split = FoodSplit::paper();
/// split.validate(&ds).unwrap();
/// assert_eq!(split.pretrain.len(), 12);
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoodSplit {
    /// Foods the estimator is pretrained on.
    pub pretrain: Vec<String>,
    /// Foods hyperparameters are chosen on.
    pub validation: Vec<String>,
    /// Foods the chosen hyperparameters are evaluated on.
    pub test: Vec<String>,
}

impl FoodSplit {
    /// The paper's split ([`hil_paper::simulation`]): validation cantaloupe,
    /// grape; test banana, carrot; the other twelve foods pretrain.
    pub fn paper() -> Self {
        let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect();
        Self {
            pretrain: v(&simulation::PRETRAIN_FOODS),
            validation: v(&simulation::VALIDATION_FOODS),
            test: v(&simulation::TEST_FOODS),
        }
    }

    /// The sets with their names, in protocol order.
    pub fn sets(&self) -> [(&'static str, &[String]); 3] {
        [
            ("pretrain", &self.pretrain),
            ("validation", &self.validation),
            ("test", &self.test),
        ]
    }

    /// Checks that every set is non-empty, every food exists in `ds`, and no
    /// food is listed twice (within or across sets).
    pub fn validate(&self, ds: &FoodDataset) -> Result<()> {
        let named = self
            .sets()
            .map(|(set, foods)| (format!("split.{set}"), foods));
        let sets: Vec<(&str, &[String])> = named.iter().map(|(n, f)| (n.as_str(), *f)).collect();
        check_disjoint(&sets, ds)
    }
}

/// Checks named food lists against `ds`: non-empty, known, disjoint. An
/// error names the list as given (`foods`), for the caller to put under
/// its table ([`HilError::within`]).
pub fn check_disjoint(sets: &[(&str, &[String])], ds: &FoodDataset) -> Result<()> {
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for (set, foods) in sets {
        if foods.is_empty() {
            return Err(HilError::invalid_parameter(*set, "[]", "the set is empty"));
        }
        for f in foods.iter() {
            if ds.food_index(f).is_none() {
                return Err(HilError::invalid_parameter(
                    *set,
                    f,
                    format!(
                        "unknown food; dataset `{}` has: {}",
                        ds.name,
                        ds.food_names().join(", ")
                    ),
                ));
            }
            if let Some((other, _)) = seen.iter().find(|(_, g)| g == f) {
                let why = if other == set {
                    format!("the food is named twice in `{set}`")
                } else {
                    format!("the food is also in `{other}`; a food may be in one list only")
                };
                return Err(HilError::invalid_parameter(*set, f, why));
            }
            seen.push((set, f));
        }
    }
    Ok(())
}
