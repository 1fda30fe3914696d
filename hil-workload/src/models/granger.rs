//! Granger-style linear models:
//! WL_t = γ·WL_0 + Σ_{i<H} w_iᵀ·onehot(query at t − i) + w_0,
//! clamped to the workload scale [0, 1].
//!
//! **Clamping (a documented choice).** Predictions are clipped to [0, 1],
//! the range of the TLX score; the paper's simulated ΔWL of exactly ±0.5
//! from WL_0 = 0.5 suggests its rollouts were clipped the same way.
//! Clipping is monotone, so it keeps "a query never lowers workload" for the
//! constrained variants, and cross-validation scores the clipped model (the
//! one that is deployed), which is why our table has no 1e+15 entries.

use hil_core::{HilError, QueryHistory, Result, Timestep, WorkloadModel, workload::check_wl0};
use serde::{Deserialize, Serialize};

use crate::features::{KIND_FEATURES, LEAD_COLUMNS, n_columns, one_hot_indices};
use hil_core::WorkloadInput;

/// The four variants of the paper plus its simulation variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GrangerVariant {
    /// Ordinary least squares.
    Plain,
    /// γ and every w_i ≥ 0.
    Nonnegative,
    /// Ridge penalty λ on γ and w_i (not on w_0).
    Ridge,
    /// Ridge and non-negativity.
    RidgeNonnegative,
    /// The simulation models: γ and every w_i in [0.05, 1], w_0 ≤ 1.
    Simulation,
}

impl GrangerVariant {
    /// The four cross-validated variants, in table order.
    pub const TABLE: [Self; 4] = [
        Self::Plain,
        Self::Nonnegative,
        Self::Ridge,
        Self::RidgeNonnegative,
    ];

    /// Label used in tables (`Granger`, `Granger-N`, ...).
    pub fn label(self) -> &'static str {
        match self {
            Self::Plain => "Granger",
            Self::Nonnegative => "Granger-N",
            Self::Ridge => "Granger-R",
            Self::RidgeNonnegative => "Granger-RN",
            Self::Simulation => "Granger-Sim",
        }
    }

    /// Short name used in CLI arguments and model names.
    pub fn key(self) -> &'static str {
        match self {
            Self::Plain => "granger",
            Self::Nonnegative => "granger_n",
            Self::Ridge => "granger_r",
            Self::RidgeNonnegative => "granger_rn",
            Self::Simulation => "granger_sim",
        }
    }

    /// True if the variant has a ridge penalty (tuned by inner CV).
    pub fn is_ridge(self) -> bool {
        matches!(self, Self::Ridge | Self::RidgeNonnegative)
    }

    /// True if every query's effect is constrained to be non-negative.
    pub fn is_monotone(self) -> bool {
        matches!(
            self,
            Self::Nonnegative | Self::RidgeNonnegative | Self::Simulation
        )
    }

    /// Coefficient bounds for design columns `[WL_0, 1, lags…]` of history h.
    pub fn bounds(self, h: usize) -> (Vec<f64>, Vec<f64>) {
        let k = n_columns(h);
        let mut lower = vec![f64::NEG_INFINITY; k];
        let mut upper = vec![f64::INFINITY; k];
        match self {
            Self::Plain | Self::Ridge => {}
            Self::Nonnegative | Self::RidgeNonnegative => {
                for (i, l) in lower.iter_mut().enumerate() {
                    if i != 1 {
                        *l = 0.0;
                    }
                }
            }
            Self::Simulation => {
                for i in 0..k {
                    if i == 1 {
                        upper[i] = 1.0;
                    } else {
                        lower[i] = 0.05;
                        upper[i] = 1.0;
                    }
                }
            }
        }
        (lower, upper)
    }
}

/// A fitted Granger model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrangerModel {
    /// How it was fitted.
    pub variant: GrangerVariant,
    /// History length H in timesteps.
    pub history: usize,
    /// Weight γ of WL_0.
    pub gamma: f64,
    /// Bias w_0.
    pub bias: f64,
    /// w_i for lags i = 0..H, each over the 8 one-hot features.
    pub weights: Vec<[f64; KIND_FEATURES]>,
    /// The ridge penalty used, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ridge_lambda: Option<f64>,
}

impl GrangerModel {
    /// Builds a model from design coefficients `[γ, w_0, lags…]`.
    pub fn from_coefficients(
        variant: GrangerVariant,
        h: usize,
        w: &[f64],
        ridge_lambda: Option<f64>,
    ) -> Result<Self> {
        if w.len() != n_columns(h) {
            return Err(HilError::invalid_input(
                "coefficients",
                format!("{} values for H = {h} (expected {})", w.len(), n_columns(h)),
            ));
        }
        let weights = (0..h)
            .map(|i| {
                let mut a = [0.0; KIND_FEATURES];
                a.copy_from_slice(
                    &w[LEAD_COLUMNS + i * KIND_FEATURES..LEAD_COLUMNS + (i + 1) * KIND_FEATURES],
                );
                a
            })
            .collect();
        let m = Self {
            variant,
            history: h,
            gamma: w[0],
            bias: w[1],
            weights,
            ridge_lambda,
        };
        m.validate()?;
        Ok(m)
    }

    /// The coefficients in design order `[γ, w_0, lags…]`.
    pub fn coefficients(&self) -> Vec<f64> {
        let mut w = vec![self.gamma, self.bias];
        for lag in &self.weights {
            w.extend_from_slice(lag);
        }
        w
    }

    /// Checks shapes and finiteness (and bounds for constrained variants).
    pub fn validate(&self) -> Result<()> {
        hil_config::limits::check_count("history", self.history, hil_config::limits::HISTORY)?;
        if self.weights.len() != self.history {
            return Err(HilError::invalid_parameter(
                "history",
                self.history,
                format!("must match the {} weight rows", self.weights.len()),
            ));
        }
        let (lower, upper) = self.variant.bounds(self.history);
        for (i, c) in self.coefficients().iter().enumerate() {
            if !c.is_finite() {
                return Err(HilError::invalid_parameter(
                    "coefficients",
                    c,
                    format!("coefficient {i} is not finite"),
                ));
            }
            // allow rounding slack from the solver
            if *c < lower[i] - 1e-9 || *c > upper[i] + 1e-9 {
                return Err(HilError::invalid_parameter(
                    "coefficients",
                    c,
                    format!(
                        "coefficient {i} is outside [{}, {}] required by {}",
                        lower[i],
                        upper[i],
                        self.variant.label()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The unclamped linear prediction.
    pub fn linear(&self, wl0: f64, history: &QueryHistory, t: Timestep) -> f64 {
        let mut s = self.gamma * wl0 + self.bias;
        for (lag, r) in history.recent(t, self.history as u64) {
            let w = &self.weights[lag as usize];
            for j in one_hot_indices(&r.kind) {
                s += w[j];
            }
        }
        s
    }
}

impl WorkloadModel for GrangerModel {
    fn name(&self) -> &str {
        self.variant.key()
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        check_wl0(input.wl0)?;
        Ok(self
            .linear(input.wl0, input.history, input.t)
            .clamp(0.0, 1.0))
    }
}
