//! Robot actions (arms) and the named action space of a task.

use std::collections::HashSet;

use serde::{Deserialize, Serialize};

use crate::error::{HilError, Result};

/// Index of a robot action in an [`ActionSpace`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ArmId(pub usize);

impl ArmId {
    /// The index as `usize`.
    pub fn index(self) -> usize {
        self.0
    }
}

impl std::fmt::Display for ArmId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// The named robot actions of a task (not including the query action).
///
/// ```
/// use hil_core::{ActionSpace, ArmId};
/// let space = ActionSpace::new(["grasp_top", "grasp_side", "push"]).unwrap();
/// assert_eq!(space.len(), 3);
/// assert_eq!(space.name(ArmId(2)).unwrap(), "push");
/// assert_eq!(space.find("grasp_side"), Some(ArmId(1)));
/// // Names are unique and non-empty.
/// assert!(ActionSpace::new(["push", "grasp_top", "push"]).is_err());
/// assert!(ActionSpace::new(["push", " "]).is_err());
/// // Read back, the same checks apply.
/// assert!(serde_json::from_str::<ActionSpace>(r#"{"names": ["a", "a"]}"#).is_err());
/// ```
///
/// Tasks define their own spaces (the feeding task's six skewering actions
/// live with the feeding data in `hil-envs`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "ActionSpaceFields")]
pub struct ActionSpace {
    names: Vec<String>,
}

/// The serde form of [`ActionSpace`], read through [`ActionSpace::new`] so
/// that deserialised names are checked as built ones are (a query or a log
/// with a duplicate or empty name is an error, not a space that breaks
/// lookups).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActionSpaceFields {
    names: Vec<String>,
}

impl TryFrom<ActionSpaceFields> for ActionSpace {
    type Error = HilError;
    fn try_from(f: ActionSpaceFields) -> Result<Self> {
        Self::new(f.names)
    }
}

impl ActionSpace {
    /// Builds an action space from unique, non-empty names.
    ///
    /// Linear in the number of names (duplicates are found with a hash set),
    /// so a manifest with hundreds of thousands of actions is checked quickly.
    pub fn new<S: Into<String>>(names: impl IntoIterator<Item = S>) -> Result<Self> {
        let names: Vec<String> = names.into_iter().map(Into::into).collect();
        if names.is_empty() {
            return Err(HilError::invalid_input("action space", "it has no actions"));
        }
        let mut seen: HashSet<&str> = HashSet::with_capacity(names.len());
        for (i, n) in names.iter().enumerate() {
            if n.trim().is_empty() {
                return Err(HilError::invalid_input(
                    format!("action name #{i}"),
                    "it is empty",
                ));
            }
            if !seen.insert(n) {
                return Err(HilError::invalid_input(
                    format!("action name #{i}"),
                    format!("`{n}` appears twice"),
                ));
            }
        }
        Ok(Self { names })
    }

    /// Number of robot actions.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Always false: an action space has at least one action.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// All names, in arm order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The name of `arm`, or an error if it is out of range.
    pub fn name(&self, arm: ArmId) -> Result<&str> {
        self.check(arm)?;
        Ok(&self.names[arm.0])
    }

    /// The arm with this name, if any.
    pub fn find(&self, name: &str) -> Option<ArmId> {
        self.names.iter().position(|n| n == name).map(ArmId)
    }

    /// Returns an error unless `arm` indexes this space.
    pub fn check(&self, arm: ArmId) -> Result<()> {
        if arm.0 < self.names.len() {
            Ok(())
        } else {
            Err(HilError::ArmOutOfRange {
                arm: arm.0,
                n_arms: self.names.len(),
            })
        }
    }

    /// Iterates over all arms.
    pub fn arms(&self) -> impl Iterator<Item = ArmId> + '_ {
        (0..self.names.len()).map(ArmId)
    }
}
