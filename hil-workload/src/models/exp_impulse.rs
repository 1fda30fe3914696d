//! Exp-Impulse: workload decays exponentially between queries and jumps by
//! an impulse β(d, resp, dist) at each query:
//! WL(t) = WL(t_prev)·e^(−λ(t − t_prev)) + β, starting from WL(0) = WL_0.
//! Time is in timesteps (Δt = 10 s); predictions are clamped to [0, 1].

use hil_core::{HilError, QueryHistory, Result, Timestep, WorkloadModel, workload::check_wl0};
use serde::{Deserialize, Serialize};

use super::impulse_sums::ImpulseSums;
use crate::datasets::TrainingPair;
use crate::features::{KIND_FEATURES, one_hot_indices};
use crate::fit::{BoxLsq, Gram};
use hil_core::WorkloadInput;

/// A fitted Exp-Impulse model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpImpulseModel {
    /// Decay rate λ per timestep (≥ 0).
    pub decay: f64,
    /// Impulse contributions of the 8 one-hot features; the impulse of a
    /// query is the sum over its three ones.
    pub impulse: [f64; KIND_FEATURES],
}

impl ExpImpulseModel {
    /// Checks λ ≥ 0 and all values finite.
    pub fn validate(&self) -> Result<()> {
        if !(self.decay.is_finite() && self.decay >= 0.0) {
            return Err(HilError::invalid_parameter(
                "decay",
                self.decay,
                "must be finite and ≥ 0",
            ));
        }
        if let Some(b) = self.impulse.iter().find(|b| !b.is_finite()) {
            return Err(HilError::invalid_parameter("impulse", b, "must be finite"));
        }
        Ok(())
    }

    /// The unclamped recursive prediction.
    pub fn linear(&self, wl0: f64, history: &QueryHistory, t: Timestep) -> f64 {
        let mut wl = wl0;
        let mut prev: Timestep = 0;
        for r in history.records().iter().filter(|r| r.t <= t) {
            wl = wl * (-self.decay * (r.t - prev) as f64).exp()
                + one_hot_indices(&r.kind)
                    .iter()
                    .map(|&j| self.impulse[j])
                    .sum::<f64>();
            prev = r.t;
        }
        wl * (-self.decay * (t - prev) as f64).exp()
    }

    /// Fits β by least squares for each λ and λ by a log-grid search
    /// refined by golden-section search (training MSE).
    ///
    /// Each λ costs O(pairs + queries): the impulse sums are carried along
    /// each condition ([`ImpulseSums`]), not summed afresh per pair.
    pub fn fit(pairs: &[&TrainingPair]) -> Result<Self> {
        if pairs.is_empty() {
            return Err(HilError::invalid_input("training set", "no pairs to fit"));
        }
        let sums = ImpulseSums::new(pairs);
        let mut features = Vec::new();
        let mut targets = Vec::with_capacity(pairs.len());
        let mut sse = |log_l: f64| -> (f64, [f64; KIND_FEATURES]) {
            let lambda = log_l.exp();
            sums.features(lambda, &mut features);
            // The target with the decayed WL_0 removed.
            targets.clear();
            targets.extend(
                pairs
                    .iter()
                    .map(|p| p.target - p.wl0 * (-lambda * p.t as f64).exp()),
            );
            let mut g = Gram::new(KIND_FEATURES);
            for (f, &y) in features.iter().zip(&targets) {
                g.add_dense(f, y);
            }
            let beta = BoxLsq::plain(&g)
                .solve(None)
                .unwrap_or_else(|_| vec![0.0; KIND_FEATURES]);
            let mut b = [0.0; KIND_FEATURES];
            b.copy_from_slice(&beta);
            let sse: f64 = features
                .iter()
                .zip(&targets)
                .map(|(f, y)| (dot(f, &b) - y).powi(2))
                .sum();
            (sse, b)
        };
        // coarse grid over λ in [1e-4, 10] per timestep
        let (lo, hi) = ((1e-4f64).ln(), (10.0f64).ln());
        let n = 24;
        let grid: Vec<f64> = (0..=n)
            .map(|i| lo + (hi - lo) * i as f64 / n as f64)
            .collect();
        let (best_i, _) =
            grid.iter()
                .map(|&x| sse(x).0)
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |acc, (i, s)| if s < acc.1 { (i, s) } else { acc },
                );
        let mut a = grid[best_i.saturating_sub(1)];
        let mut b = grid[(best_i + 1).min(n)];
        let phi = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..40 {
            let c = b - phi * (b - a);
            let d = a + phi * (b - a);
            if sse(c).0 < sse(d).0 {
                b = d;
            } else {
                a = c;
            }
        }
        let mid = 0.5 * (a + b);
        let cands = [grid[best_i], mid];
        let best = cands
            .iter()
            .map(|&x| (x, sse(x)))
            .fold(
                None::<(f64, (f64, [f64; KIND_FEATURES]))>,
                |acc, c| match acc {
                    Some(a) if a.1.0 <= c.1.0 => Some(a),
                    _ => Some(c),
                },
            )
            .expect("two candidates");
        let m = Self {
            decay: best.0.exp(),
            impulse: best.1.1,
        };
        m.validate()?;
        Ok(m)
    }

    /// The clamped predictions for `pairs` (each at its own time, from its
    /// own prefix), in O(pairs + queries): what [`WorkloadModel::predict`]
    /// gives pair by pair, to rounding.
    pub fn predict_pairs(&self, pairs: &[&TrainingPair]) -> Vec<f64> {
        let mut features = Vec::new();
        ImpulseSums::new(pairs).features(self.decay, &mut features);
        pairs
            .iter()
            .zip(&features)
            .map(|(p, f)| {
                let offset = p.wl0 * (-self.decay * p.t as f64).exp();
                (offset + dot(f, &self.impulse)).clamp(0.0, 1.0)
            })
            .collect()
    }
}

fn dot(a: &[f64; KIND_FEATURES], b: &[f64; KIND_FEATURES]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl WorkloadModel for ExpImpulseModel {
    fn name(&self) -> &str {
        "exp_impulse"
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        check_wl0(input.wl0)?;
        Ok(self
            .linear(input.wl0, input.history, input.t)
            .clamp(0.0, 1.0))
    }
}
