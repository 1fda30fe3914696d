//! Exact least-squares solvers on normal equations: ridge and
//! bound-constrained (box) least squares.
//!
//! Problems are posed on a Gram matrix `G = XᵀX`, `b = Xᵀy`:
//!
//! minimise ½·wᵀ(G + diag(ρ))w − bᵀw  subject to  l ≤ w ≤ u,
//!
//! where ρ is a per-coefficient ridge penalty (0 for unpenalised ones) and
//! bounds may be infinite. The solver is a primal active-set method whose
//! subproblems are solved with a diagonally pivoted Cholesky factorisation,
//! so rank-deficient designs (one-hot groups are collinear with the bias)
//! get an exact basic least-squares solution instead of a failure. It is
//! cross-checked against clarabel in the tests.

use hil_core::{HilError, Result};

use crate::features::SparseRow;

/// Accumulated normal equations of a set of rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Gram {
    /// Number of columns.
    pub k: usize,
    /// `XᵀX`, row-major k×k.
    pub g: Vec<f64>,
    /// `Xᵀy`.
    pub b: Vec<f64>,
    /// `yᵀy`.
    pub yy: f64,
    /// Number of rows.
    pub n: usize,
}

impl Gram {
    /// Empty normal equations with `k` columns.
    pub fn new(k: usize) -> Self {
        Self {
            k,
            g: vec![0.0; k * k],
            b: vec![0.0; k],
            yy: 0.0,
            n: 0,
        }
    }

    /// Adds one row (entries beyond column k are ignored).
    pub fn add_row(&mut self, row: &SparseRow) {
        let k = self.k;
        for &(i, vi) in row.entries.iter().filter(|(c, _)| *c < k) {
            self.b[i] += vi * row.y;
            for &(j, vj) in row.entries.iter().filter(|(c, _)| *c < k) {
                self.g[i * k + j] += vi * vj;
            }
        }
        self.yy += row.y * row.y;
        self.n += 1;
    }

    /// Adds one dense row `x` (length k) with target `y`.
    pub fn add_dense(&mut self, x: &[f64], y: f64) {
        let k = self.k;
        debug_assert_eq!(x.len(), k);
        for (i, &vi) in x.iter().enumerate() {
            self.b[i] += vi * y;
            for (g, &vj) in self.g[i * k..(i + 1) * k].iter_mut().zip(x) {
                *g += vi * vj;
            }
        }
        self.yy += y * y;
        self.n += 1;
    }

    /// `self += sign · other` (same k).
    pub fn accumulate(&mut self, other: &Gram, sign: f64) {
        for (a, b) in self.g.iter_mut().zip(&other.g) {
            *a += sign * b;
        }
        for (a, b) in self.b.iter_mut().zip(&other.b) {
            *a += sign * b;
        }
        self.yy += sign * other.yy;
        if sign >= 0.0 {
            self.n += other.n;
        } else {
            self.n -= other.n;
        }
    }

    /// The normal equations of the first `k` columns.
    pub fn prefix(&self, k: usize) -> Gram {
        let mut g = Vec::with_capacity(k * k);
        for i in 0..k {
            g.extend_from_slice(&self.g[i * self.k..i * self.k + k]);
        }
        Gram {
            k,
            g,
            b: self.b[..k].to_vec(),
            yy: self.yy,
            n: self.n,
        }
    }
}

/// Solves `A[idx,idx] z = rhs` for symmetric positive semi-definite `A`
/// (row-major, `k` columns) with a diagonally pivoted Cholesky
/// factorisation. Directions whose pivot falls below `1e-11 × max pivot`
/// are treated as dependent and get 0 (a basic least-squares solution).
pub fn solve_psd(a: &[f64], k: usize, idx: &[usize], rhs: &[f64]) -> Vec<f64> {
    if let Some(z) = solve_pd(a, k, idx, rhs) {
        return z;
    }
    solve_pivoted(a, k, idx, rhs)
}

/// Unpivoted Cholesky (dot-product form on contiguous rows): the fast path
/// for well-conditioned (e.g. ridge) systems. None if a pivot falls below
/// the rank tolerance, in which case the pivoted path decides the rank.
fn solve_pd(a: &[f64], k: usize, idx: &[usize], rhs: &[f64]) -> Option<Vec<f64>> {
    let m = idx.len();
    let max_diag = idx.iter().map(|&i| a[i * k + i]).fold(0.0f64, f64::max);
    let tol = 1e-8 * max_diag.max(f64::MIN_POSITIVE);
    let mut l = vec![0.0; m * m];
    for (r, &i) in idx.iter().enumerate() {
        for c in 0..=r {
            let (row_r, row_c) = (&l[r * m..r * m + c], &l[c * m..c * m + c]);
            let dot: f64 = row_r.iter().zip(row_c).map(|(x, y)| x * y).sum();
            let v = a[i * k + idx[c]] - dot;
            if c == r {
                if v <= tol {
                    return None;
                }
                l[r * m + r] = v.sqrt();
            } else {
                l[r * m + c] = v / l[c * m + c];
            }
        }
    }
    let mut z = rhs.to_vec();
    for i in 0..m {
        let dot: f64 = l[i * m..i * m + i]
            .iter()
            .zip(&z[..i])
            .map(|(x, y)| x * y)
            .sum();
        z[i] = (z[i] - dot) / l[i * m + i];
    }
    for i in (0..m).rev() {
        let mut s = z[i];
        for r in i + 1..m {
            s -= l[r * m + i] * z[r];
        }
        z[i] = s / l[i * m + i];
    }
    Some(z)
}

/// Diagonally pivoted Cholesky with rank detection (basic solution).
fn solve_pivoted(a: &[f64], k: usize, idx: &[usize], rhs: &[f64]) -> Vec<f64> {
    let m = idx.len();
    let mut l = vec![0.0; m * m];
    for (r, &i) in idx.iter().enumerate() {
        for (c, &j) in idx.iter().enumerate() {
            l[r * m + c] = a[i * k + j];
        }
    }
    let mut perm: Vec<usize> = (0..m).collect();
    let max_diag = (0..m).map(|i| l[i * m + i]).fold(0.0f64, f64::max);
    let tol = 1e-11 * max_diag.max(f64::MIN_POSITIVE);
    let mut rank = 0;
    for j in 0..m {
        // pick the largest remaining pivot
        let (p, piv) = (j..m)
            .map(|i| (i, l[i * m + i]))
            .fold(
                (j, f64::NEG_INFINITY),
                |acc, x| if x.1 > acc.1 { x } else { acc },
            );
        if piv <= tol {
            break;
        }
        if p != j {
            // symmetric swap of rows/columns j and p
            for c in 0..m {
                l.swap(j * m + c, p * m + c);
            }
            for r in 0..m {
                l.swap(r * m + j, r * m + p);
            }
            perm.swap(j, p);
        }
        let d = l[j * m + j].sqrt();
        l[j * m + j] = d;
        for i in j + 1..m {
            l[i * m + j] /= d;
        }
        for i in j + 1..m {
            l[j * m + i] = l[i * m + j];
        }
        // right-looking update of the (full, symmetric) trailing block
        for i in j + 1..m {
            let lij = l[i * m + j];
            if lij == 0.0 {
                continue;
            }
            for c in j + 1..m {
                l[i * m + c] -= lij * l[j * m + c];
            }
        }
        rank = j + 1;
    }
    // forward/back substitution on the leading rank×rank block
    let mut z: Vec<f64> = perm.iter().map(|&p| rhs[p]).collect();
    for i in 0..rank {
        let mut s = z[i];
        for c in 0..i {
            s -= l[i * m + c] * z[c];
        }
        z[i] = s / l[i * m + i];
    }
    for i in (0..rank).rev() {
        let mut s = z[i];
        for r in i + 1..rank {
            s -= l[r * m + i] * z[r];
        }
        z[i] = s / l[i * m + i];
    }
    for zi in z.iter_mut().skip(rank) {
        *zi = 0.0;
    }
    let mut out = vec![0.0; m];
    for (pos, &p) in perm.iter().enumerate() {
        out[p] = z[pos];
    }
    out
}

/// A box-constrained ridge least-squares problem on normal equations.
#[derive(Clone, Debug)]
pub struct BoxLsq<'a> {
    /// The normal equations.
    pub gram: &'a Gram,
    /// Per-coefficient ridge penalty ρ (length k).
    pub ridge: Vec<f64>,
    /// Lower bounds (−∞ allowed).
    pub lower: Vec<f64>,
    /// Upper bounds (+∞ allowed).
    pub upper: Vec<f64>,
}

impl<'a> BoxLsq<'a> {
    /// Unconstrained, unpenalised least squares.
    pub fn plain(gram: &'a Gram) -> Self {
        Self {
            gram,
            ridge: vec![0.0; gram.k],
            lower: vec![f64::NEG_INFINITY; gram.k],
            upper: vec![f64::INFINITY; gram.k],
        }
    }

    /// The objective ½·wᵀ(G + diag ρ)w − bᵀw.
    pub fn objective(&self, w: &[f64]) -> f64 {
        let k = self.gram.k;
        let mut s = 0.0;
        for i in 0..k {
            let gw: f64 =
                (0..k).map(|j| self.gram.g[i * k + j] * w[j]).sum::<f64>() + self.ridge[i] * w[i];
            s += 0.5 * w[i] * gw - self.gram.b[i] * w[i];
        }
        s
    }

    /// Solves the problem exactly (up to rounding) by a primal active-set
    /// method, starting from `start` projected onto the box (or from 0).
    pub fn solve(&self, start: Option<&[f64]>) -> Result<Vec<f64>> {
        let k = self.gram.k;
        if self.ridge.len() != k || self.lower.len() != k || self.upper.len() != k {
            return Err(HilError::invalid_input(
                "least-squares problem",
                "bounds or penalties have the wrong length",
            ));
        }
        for i in 0..k {
            if self.lower[i] > self.upper[i]
                || self.ridge[i] < 0.0
                || self.lower[i].is_nan()
                || self.upper[i].is_nan()
            {
                return Err(HilError::invalid_input(
                    "least-squares problem",
                    format!("coefficient {i} has empty bounds or a negative penalty"),
                ));
            }
        }
        let mut h = self.gram.g.clone();
        for i in 0..k {
            h[i * k + i] += self.ridge[i];
        }
        let b = &self.gram.b;
        // Without a warm start, begin at the unconstrained minimiser clipped
        // to the box: most coefficients are then already on the right side
        // of their bounds, so few active-set changes remain.
        let bounded = (0..k).any(|i| self.lower[i].is_finite() || self.upper[i].is_finite());
        let unconstrained;
        let start = match start {
            Some(s) => Some(s),
            None if bounded => {
                let all: Vec<usize> = (0..k).filter(|&i| h[i * k + i] > 0.0).collect();
                let rhs: Vec<f64> = all.iter().map(|&i| b[i]).collect();
                let z = solve_psd(&h, k, &all, &rhs);
                let mut full = vec![0.0; k];
                for (pos, &i) in all.iter().enumerate() {
                    full[i] = z[pos];
                }
                unconstrained = full;
                Some(unconstrained.as_slice())
            }
            None => None,
        };
        let mut x: Vec<f64> = (0..k)
            .map(|i| {
                start
                    .map_or(0.0, |s| s[i])
                    .clamp(self.lower[i], self.upper[i])
            })
            .collect();
        // Coefficients of all-zero columns do not affect the objective:
        // they stay at their (projected) start value.
        let live: Vec<bool> = (0..k).map(|i| h[i * k + i] > 0.0).collect();
        let mut free: Vec<bool> = (0..k)
            .map(|i| live[i] && x[i] > self.lower[i] && x[i] < self.upper[i])
            .collect();
        let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let tol = 1e-10 * scale;
        let grad = |x: &[f64], i: usize| -> f64 {
            (0..k).map(|j| h[i * k + j] * x[j]).sum::<f64>() - b[i]
        };
        let max_iter = 20 * k + 200;
        for _ in 0..max_iter {
            let idx: Vec<usize> = (0..k).filter(|&i| free[i]).collect();
            if !idx.is_empty() {
                let rhs: Vec<f64> = idx.iter().map(|&i| -grad(&x, i)).collect();
                let d = solve_psd(&h, k, &idx, &rhs);
                let mut alpha = 1.0;
                let mut blocking: Option<(usize, f64)> = None;
                for (pos, &i) in idx.iter().enumerate() {
                    let di = d[pos];
                    if di < 0.0 && self.lower[i].is_finite() {
                        let a = (self.lower[i] - x[i]) / di;
                        if a < alpha {
                            alpha = a.max(0.0);
                            blocking = Some((i, self.lower[i]));
                        }
                    } else if di > 0.0 && self.upper[i].is_finite() {
                        let a = (self.upper[i] - x[i]) / di;
                        if a < alpha {
                            alpha = a.max(0.0);
                            blocking = Some((i, self.upper[i]));
                        }
                    }
                }
                for (pos, &i) in idx.iter().enumerate() {
                    x[i] = (x[i] + alpha * d[pos]).clamp(self.lower[i], self.upper[i]);
                }
                if let Some((i, bound)) = blocking {
                    x[i] = bound;
                    free[i] = false;
                    continue;
                }
            }
            // subspace optimum: release the bound with the worst multiplier
            let mut worst: Option<(usize, f64)> = None;
            for i in (0..k).filter(|&i| live[i] && !free[i]) {
                let g = grad(&x, i);
                let violation = if x[i] <= self.lower[i] && g < -tol {
                    -g
                } else if x[i] >= self.upper[i] && g > tol {
                    g
                } else {
                    0.0
                };
                if violation > 0.0 && worst.is_none_or(|(_, v)| violation > v) {
                    worst = Some((i, violation));
                }
            }
            match worst {
                None => return Ok(x),
                Some((i, _)) => free[i] = true,
            }
        }
        Err(HilError::state(
            "bounded least squares",
            format!("the active-set method did not converge in {max_iter} iterations"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gram_of(rows: &[(Vec<f64>, f64)]) -> Gram {
        let k = rows[0].0.len();
        let mut g = Gram::new(k);
        for (x, y) in rows {
            g.add_row(&SparseRow {
                entries: x.iter().copied().enumerate().collect(),
                y: *y,
            });
        }
        g
    }

    #[test]
    fn plain_least_squares_recovers_exact_fit() {
        let rows: Vec<_> = (0..10)
            .map(|i| {
                let a = i as f64;
                (
                    vec![1.0, a, (a * 0.7).sin()],
                    2.0 - 0.5 * a + 3.0 * (a * 0.7).sin(),
                )
            })
            .collect();
        let g = gram_of(&rows);
        let w = BoxLsq::plain(&g).solve(None).unwrap();
        for (wi, ti) in w.iter().zip([2.0, -0.5, 3.0]) {
            assert!((wi - ti).abs() < 1e-9, "{w:?}");
        }
    }

    #[test]
    fn rank_deficient_gives_a_minimiser() {
        // column 2 = column 0 + column 1
        let rows: Vec<_> = (0..8)
            .map(|i| {
                let a = i as f64;
                (vec![1.0, a, 1.0 + a], 1.0 + 2.0 * a)
            })
            .collect();
        let g = gram_of(&rows);
        let p = BoxLsq::plain(&g);
        let w = p.solve(None).unwrap();
        let resid: f64 = rows
            .iter()
            .map(|(x, y)| (x.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>() - y).powi(2))
            .sum();
        assert!(resid < 1e-18, "{w:?} {resid}");
    }

    #[test]
    fn nonnegativity_is_respected_and_kkt_holds() {
        let rows: Vec<_> = (0..12)
            .map(|i| {
                let a = i as f64;
                (
                    vec![1.0, a, (a * 1.3).cos()],
                    1.0 - 0.3 * a + 0.2 * (a * 1.3).cos(),
                )
            })
            .collect();
        let g = gram_of(&rows);
        let mut p = BoxLsq::plain(&g);
        p.lower = vec![f64::NEG_INFINITY, 0.0, 0.0];
        let w = p.solve(None).unwrap();
        assert!(w[1] >= 0.0 && w[2] >= 0.0);
        assert_eq!(w[1], 0.0, "{w:?}");
        // KKT: gradient zero on free coordinates, ≥ 0 at the lower bound
        let gr: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| g.g[i * 3 + j] * w[j]).sum::<f64>() - g.b[i])
            .collect();
        assert!(gr[0].abs() < 1e-9 && gr[1] >= -1e-9, "{gr:?}");
    }
}
