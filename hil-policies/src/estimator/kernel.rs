//! Kernel (Woodbury) form of one arm, for few observations compared with d.
//!
//! With X the arm's n × d observations and K = λI + XXᵀ = LLᵀ (n × n):
//! - θᵀx = rᵀK⁻¹Xx = cᵀz with c = L⁻¹r and z = L⁻¹k, k = Xx;
//! - xᵀA⁻¹x = (xᵀx − kᵀK⁻¹k)/λ = (xᵀx − zᵀz)/λ.
//!
//! A score costs the product k = Xx (O(n·d), shared across arms through the
//! row store) plus one triangular solve (O(n²)). Appending an observation
//! grows L by one row, and that row is exactly the z already computed for
//! scoring, so an update is O(n) once scored.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Side};

use super::linalg::{dot, forward_solve_row_packed, packed_len, row_packed_offset};
use super::store::RowStore;
use hil_core::{HilError, Result};

#[derive(Clone, Debug, Default)]
pub(crate) struct KernelArm {
    /// Store indices of the observations, in order.
    pub(crate) rows: Vec<u32>,
    /// Row-packed lower Cholesky factor of λI + XXᵀ.
    l: Vec<f64>,
    /// c = L⁻¹r.
    c: Vec<f64>,
}

impl KernelArm {
    pub(crate) fn n(&self) -> usize {
        self.rows.len()
    }

    /// Builds the arm from its observations in one batch (Gram matrix and
    /// Cholesky factor through faer).
    pub(crate) fn build(
        rows: Vec<u32>,
        rewards: Vec<f64>,
        store: &RowStore,
        dim: usize,
        lambda: f64,
    ) -> Result<Self> {
        let n = rows.len();
        let x = Mat::<f64>::from_fn(n, dim, |i, j| store.row(rows[i] as usize)[j]);
        let mut k = Mat::<f64>::zeros(n, n);
        matmul(
            &mut k,
            Accum::Replace,
            &x,
            x.transpose(),
            1.0,
            faer::get_global_parallelism(),
        );
        for i in 0..n {
            k[(i, i)] += lambda;
        }
        let llt = k.llt(Side::Lower).map_err(|e| {
            HilError::numerical(
                "linear arms: Cholesky factorisation of the kernel matrix",
                e,
            )
        })?;
        let lm = llt.L();
        let mut l = Vec::with_capacity(packed_len(n));
        for i in 0..n {
            for j in 0..=i {
                l.push(lm[(i, j)]);
            }
        }
        let mut c = rewards.clone();
        forward_solve_row_packed(&l, &mut c);
        Ok(Self { rows, l, c })
    }

    /// Gathers k = Xx from the per-row products `g` into `z`, then turns it
    /// into z = L⁻¹k. Returns (θᵀx, xᵀA⁻¹x).
    pub(crate) fn score_from_products(
        &self,
        g: &[f64],
        xx: f64,
        lambda: f64,
        z: &mut Vec<f64>,
    ) -> (f64, f64) {
        z.clear();
        z.extend(self.rows.iter().map(|&r| g[r as usize]));
        self.finish_score(xx, lambda, z)
    }

    /// Like [`Self::score_from_products`], computing the products from the
    /// store (all rows, so that the numbers are bit-identical to the ones a
    /// scoring pass produces: checkpoint replay depends on it).
    pub(crate) fn score_direct(
        &self,
        store: &RowStore,
        x: &[f64],
        lambda: f64,
        z: &mut Vec<f64>,
    ) -> (f64, f64) {
        let mut g = Vec::new();
        store.products(x, &mut g);
        self.score_from_products(&g, dot(x, x), lambda, z)
    }

    fn finish_score(&self, xx: f64, lambda: f64, z: &mut [f64]) -> (f64, f64) {
        forward_solve_row_packed(&self.l, z);
        let est = dot(&self.c, z);
        // xᵀx − zᵀz ≥ 0 in exact arithmetic; clamp the rounding.
        let q = ((xx - dot(z, z)) / lambda).max(0.0);
        (est, q)
    }

    /// Appends an observation whose z = L⁻¹Xx (from scoring) is `z`.
    pub(crate) fn push(&mut self, row: u32, z: &[f64], xx: f64, reward: f64, lambda: f64) {
        debug_assert_eq!(z.len(), self.n());
        // The new pivot is λ(1 + xᵀA⁻¹x) ≥ λ > 0, so it never vanishes, even
        // for duplicate or collinear contexts.
        let pivot = (lambda + (xx - dot(z, z)).max(0.0)).sqrt();
        let cn = (reward - dot(z, &self.c)) / pivot;
        self.l.extend_from_slice(z);
        self.l.push(pivot);
        self.c.push(cn);
        self.rows.push(row);
    }

    /// θ = Xᵀ K⁻¹ r = Xᵀ L⁻ᵀ c, explicitly (O(n·d); for inspection).
    pub(crate) fn theta(&self, store: &RowStore, dim: usize) -> Vec<f64> {
        let n = self.n();
        let mut beta = self.c.clone();
        for i in (0..n).rev() {
            let off = row_packed_offset(i);
            beta[i] /= self.l[off + i];
            let bi = beta[i];
            for (bj, lij) in beta[..i].iter_mut().zip(&self.l[off..off + i]) {
                *bj -= lij * bi;
            }
        }
        let mut theta = vec![0.0; dim];
        for (&r, &bi) in self.rows.iter().zip(&beta) {
            for (t, v) in theta.iter_mut().zip(store.row(r as usize)) {
                *t += bi * v;
            }
        }
        theta
    }

    pub(crate) fn factor_bytes(&self) -> usize {
        self.l.len() * std::mem::size_of::<f64>()
    }

    pub(crate) fn remap(&mut self, map: &[u32]) {
        for r in &mut self.rows {
            *r = map[*r as usize];
        }
    }
}
