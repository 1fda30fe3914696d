//! Dense factorised form of one arm, for many observations.
//!
//! Keeps the Cholesky factor L of A = λI + XᵀX, packed by columns (lower
//! triangle only: half the bytes of a full matrix), b = Xᵀr and c = L⁻¹b.
//! A score is one forward solve z = L⁻¹x, streaming L once:
//! θᵀx = bᵀA⁻¹x = cᵀz and xᵀA⁻¹x = zᵀz. An update is one fused pass that
//! applies the rank-one Cholesky update and re-solves c against the new
//! factor, column by column, while each column is in cache.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Side};

use super::linalg::{dot, forward_solve_col_packed, packed_len};
use hil_core::{HilError, Result};

#[derive(Clone, Debug)]
pub(crate) struct DenseArm {
    dim: usize,
    /// Column-packed lower Cholesky factor of A.
    l: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    n: usize,
}

impl DenseArm {
    /// Builds the arm from its `n × dim` observations `x` in one batch.
    pub(crate) fn build(x: &Mat<f64>, rewards: &[f64], lambda: f64) -> Result<Self> {
        let (n, dim) = (x.nrows(), x.ncols());
        let par = faer::get_global_parallelism();
        let mut a = Mat::<f64>::zeros(dim, dim);
        matmul(&mut a, Accum::Replace, x.transpose(), x, 1.0, par);
        for i in 0..dim {
            a[(i, i)] += lambda;
        }
        let mut b = vec![0.0; dim];
        for (i, r) in rewards.iter().enumerate() {
            for (j, bj) in b.iter_mut().enumerate() {
                *bj += r * x[(i, j)];
            }
        }
        let llt = a.llt(Side::Lower).map_err(|e| {
            HilError::numerical("linear arms: Cholesky factorisation of λI + XᵀX", e)
        })?;
        let lm = llt.L();
        let mut l = Vec::with_capacity(packed_len(dim));
        for j in 0..dim {
            for i in j..dim {
                l.push(lm[(i, j)]);
            }
        }
        let mut c = b.clone();
        forward_solve_col_packed(&l, &mut c);
        Ok(Self { dim, l, b, c, n })
    }

    /// Writes z = L⁻¹x into `w`; returns (θᵀx, xᵀA⁻¹x).
    pub(crate) fn score(&self, x: &[f64], w: &mut Vec<f64>) -> (f64, f64) {
        w.clear();
        w.extend_from_slice(x);
        forward_solve_col_packed(&self.l, w);
        (dot(&self.c, w), dot(w, w))
    }

    /// Adds one observation: L ← chol(LLᵀ + xxᵀ), b ← b + r·x, c ← L⁻¹b,
    /// in one pass over L.
    pub(crate) fn update(&mut self, x: &[f64], reward: f64) {
        for (bi, xi) in self.b.iter_mut().zip(x) {
            *bi += reward * xi;
        }
        let mut w = x.to_vec();
        let mut v = self.b.clone();
        super::linalg::rank_one_update_col_packed(&mut self.l, &mut w, &mut v, &mut self.c);
        self.n += 1;
    }

    /// θ = L⁻ᵀc, explicitly.
    pub(crate) fn theta(&self) -> Vec<f64> {
        let d = self.dim;
        let mut t = self.c.clone();
        for j in (0..d).rev() {
            let off = super::linalg::col_packed_offset(d, j);
            let col = &self.l[off..off + (d - j)];
            let s = dot(&col[1..], &t[j + 1..]);
            t[j] = (t[j] - s) / col[0];
        }
        t
    }

    pub(crate) fn n(&self) -> usize {
        self.n
    }

    pub(crate) fn factor_bytes(&self) -> usize {
        self.l.len() * std::mem::size_of::<f64>()
    }
}
