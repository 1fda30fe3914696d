//! The paper's four methods: their labels (as the paper's tables print
//! them), the hil policy type that implements each, and the grid hil tunes
//! each over on the validation foods.

/// One of the paper's methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PaperMethod {
    /// LinUCB, the fully autonomous baseline: never asks.
    LinUcb,
    /// AlwaysQuery: asks for every item.
    AlwaysQuery,
    /// LinUCB-ExpDecay: asks with a probability that decays exponentially
    /// in time, at rate `c`.
    LinUcbExpDecay,
    /// LinUCB-QG, the paper's method: asks when the confidence-bound gap
    /// exceeds `w` times the predicted workload.
    LinUcbQg,
}

/// Label of [`PaperMethod::LinUcb`].
pub const LINUCB: &str = "LinUCB";
/// Label of [`PaperMethod::AlwaysQuery`].
pub const ALWAYS_QUERY: &str = "AlwaysQuery";
/// Label of [`PaperMethod::LinUcbExpDecay`].
pub const LINUCB_EXPDECAY: &str = "LinUCB-ExpDecay";
/// Label of [`PaperMethod::LinUcbQg`].
pub const LINUCB_QG: &str = "LinUCB-QG";

/// hil's grid of ExpDecay's decay rate `c` (the paper does not print its
/// grid). `c = 0` never decays, i.e. always asks.
pub const EXPDECAY_C_GRID: [f64; 8] = [0.0, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0];

/// hil's grid of LinUCB-QG's workload weight `w` (the paper does not print
/// its grid): powers of two from 1/4 to 32.
pub const QG_W_GRID: [f64; 8] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];

/// The UCB confidence weight α of every method. The paper does not state
/// it; this is hil's, for the testbed and the user study alike.
pub const ALPHA: f64 = 0.5;

impl PaperMethod {
    /// The four methods, in the order the paper's tables list them.
    pub const ALL: [Self; 4] = [
        Self::LinUcb,
        Self::AlwaysQuery,
        Self::LinUcbExpDecay,
        Self::LinUcbQg,
    ];

    /// The label the paper's tables (and hil's reports) print.
    pub const fn label(self) -> &'static str {
        match self {
            Self::LinUcb => LINUCB,
            Self::AlwaysQuery => ALWAYS_QUERY,
            Self::LinUcbExpDecay => LINUCB_EXPDECAY,
            Self::LinUcbQg => LINUCB_QG,
        }
    }

    /// The method whose label is `label`, if it is one of the paper's.
    pub fn from_label(label: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.label() == label)
    }

    /// The hil policy type (its name in configs) that implements the method.
    pub const fn policy_type(self) -> &'static str {
        match self {
            Self::LinUcb => "linucb",
            Self::AlwaysQuery => "always_query",
            Self::LinUcbExpDecay => "linucb_exp_decay",
            Self::LinUcbQg => "linucb_qg",
        }
    }

    /// The hyperparameter hil tunes on validation and its grid, if any.
    ///
    /// ```
    /// use hil_paper::methods::{PaperMethod, QG_W_GRID};
    /// assert_eq!(PaperMethod::LinUcbQg.tuned(), Some(("w", &QG_W_GRID[..])));
    /// assert_eq!(PaperMethod::LinUcb.tuned(), None);
    /// ```
    pub const fn tuned(self) -> Option<(&'static str, &'static [f64])> {
        match self {
            Self::LinUcb | Self::AlwaysQuery => None,
            Self::LinUcbExpDecay => Some(("c", &EXPDECAY_C_GRID)),
            Self::LinUcbQg => Some(("w", &QG_W_GRID)),
        }
    }
}

impl std::fmt::Display for PaperMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_unique_and_round_trip() {
        for m in PaperMethod::ALL {
            assert_eq!(PaperMethod::from_label(m.label()), Some(m));
        }
        assert_eq!(PaperMethod::from_label("LinUCB-qg"), None);
    }

    #[test]
    fn grids_are_strictly_increasing() {
        for grid in [&EXPDECAY_C_GRID[..], &QG_W_GRID[..]] {
            assert!(grid.windows(2).all(|w| w[0] < w[1]));
        }
    }
}
