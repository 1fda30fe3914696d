//! How the estimator picks its per-arm representation.

use serde::{Deserialize, Serialize};

use hil_core::{HilError, Result};

/// The per-arm storage an estimator uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Representation {
    /// Kernel (Woodbury) form: the arm's observations and the Cholesky
    /// factor of λI + XXᵀ (n × n). Cost per score O(n·d + n²).
    Kernel,
    /// Dense form: the packed Cholesky factor of λI + XᵀX (d × d).
    /// Cost per score O(d²).
    Dense,
}

/// Which representation to use: chosen by cost, or forced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RepresentationChoice {
    /// Kernel form while an arm has fewer than `crossover · d`
    /// observations, dense beyond.
    #[default]
    Auto,
    /// Always the kernel form.
    Kernel,
    /// Always the dense form.
    Dense,
}

/// Default crossover, as a fraction of d (see [`EstimatorOptions::crossover`]).
///
/// Per score, an arm in kernel form streams n·d + n²/2 numbers (its rows and
/// its factor) and one in dense form d²/2, so the byte counts cross at
/// n ≈ (√2 − 1)·d ≈ 0.41·d. Measured with `hil bench policy` at d = 2048
/// (single arm, private contexts), kernel and dense per-step times cross
/// near the same point; see the crate README for the numbers.
pub const DEFAULT_CROSSOVER: f64 = 0.41;

/// Estimator options beyond λ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimatorOptions {
    /// Representation policy.
    pub representation: RepresentationChoice,
    /// With `Auto`, an arm switches to the dense form once it has at least
    /// `crossover · d` observations. Must be finite and > 0.
    pub crossover: f64,
}

impl Default for EstimatorOptions {
    fn default() -> Self {
        Self {
            representation: RepresentationChoice::Auto,
            crossover: DEFAULT_CROSSOVER,
        }
    }
}

impl EstimatorOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<()> {
        if !(self.crossover.is_finite() && self.crossover > 0.0) {
            return Err(HilError::invalid_parameter(
                "crossover",
                self.crossover,
                "must be a finite number > 0 (a fraction of the context dimension)",
            ));
        }
        Ok(())
    }

    /// The representation for an arm with `n` observations in dimension `dim`.
    pub fn target(&self, n: usize, dim: usize) -> Representation {
        match self.representation {
            RepresentationChoice::Kernel => Representation::Kernel,
            RepresentationChoice::Dense => Representation::Dense,
            RepresentationChoice::Auto => {
                if (n as f64) < self.crossover * dim as f64 {
                    Representation::Kernel
                } else {
                    Representation::Dense
                }
            }
        }
    }
}
