//! A deliberately naive reference estimator: builds A = λI + XᵀX and its
//! inverse directly (LU with partial pivoting through faer) for every query.
//! O(n·d² + d³) per call; it exists to check the fast representations.

use faer::Mat;
use faer::linalg::solvers::DenseSolveCore;

use super::ArmEstimate;
use hil_core::{HilError, Result};

/// Per-arm observation lists, solved from scratch on demand.
#[derive(Clone, Debug)]
pub struct NaiveArms {
    dim: usize,
    lambda: f64,
    data: Vec<(Vec<Vec<f64>>, Vec<f64>)>,
}

impl NaiveArms {
    /// `n_arms` empty arms.
    pub fn new(n_arms: usize, dim: usize, lambda: f64) -> Self {
        Self {
            dim,
            lambda,
            data: vec![(Vec::new(), Vec::new()); n_arms],
        }
    }

    /// Records an observation.
    pub fn push(&mut self, arm: usize, x: &[f64], reward: f64) {
        self.data[arm].0.push(x.to_vec());
        self.data[arm].1.push(reward);
    }

    /// A⁻¹ for `arm`, by direct inversion.
    pub fn inverse(&self, arm: usize) -> Result<Mat<f64>> {
        let d = self.dim;
        let (xs, _) = self
            .data
            .get(arm)
            .ok_or_else(|| HilError::invalid_input("arm", format!("{arm} is out of range")))?;
        let mut a = Mat::<f64>::zeros(d, d);
        for i in 0..d {
            a[(i, i)] = self.lambda;
        }
        for x in xs {
            for i in 0..d {
                for j in 0..d {
                    a[(i, j)] += x[i] * x[j];
                }
            }
        }
        Ok(a.partial_piv_lu().inverse())
    }

    /// θ = A⁻¹b for `arm`.
    pub fn theta(&self, arm: usize) -> Result<Vec<f64>> {
        let inv = self.inverse(arm)?;
        let (xs, rs) = &self.data[arm];
        let d = self.dim;
        let mut b = vec![0.0; d];
        for (x, r) in xs.iter().zip(rs) {
            for j in 0..d {
                b[j] += r * x[j];
            }
        }
        Ok((0..d)
            .map(|i| (0..d).map(|j| inv[(i, j)] * b[j]).sum())
            .collect())
    }

    /// θᵀx and sqrt(xᵀA⁻¹x) for `arm`.
    pub fn estimate(&self, arm: usize, x: &[f64]) -> Result<ArmEstimate> {
        let inv = self.inverse(arm)?;
        let theta = self.theta(arm)?;
        let d = self.dim;
        let est = theta.iter().zip(x).map(|(t, v)| t * v).sum();
        let mut q = 0.0;
        for i in 0..d {
            for j in 0..d {
                q += x[i] * inv[(i, j)] * x[j];
            }
        }
        Ok(ArmEstimate {
            estimate: est,
            bonus: q.max(0.0).sqrt(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_observation_by_hand() {
        // λ = 1, x = e₁, r = 1: A = diag(2, 1), θ = (0.5, 0), bonus √0.5.
        let mut n = NaiveArms::new(1, 2, 1.0);
        n.push(0, &[1.0, 0.0], 1.0);
        let e = n.estimate(0, &[1.0, 0.0]).unwrap();
        assert!((e.estimate - 0.5).abs() < 1e-15);
        assert!((e.bonus - 0.5f64.sqrt()).abs() < 1e-15);
    }
}
