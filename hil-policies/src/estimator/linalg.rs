//! Small streaming kernels over packed triangular storage.
//!
//! The per-step cost of the estimator is memory traffic, so these loops are
//! written to stream their matrices once, front to back, with fixed
//! accumulation orders (results are bit-reproducible run to run, which the
//! checkpoint replay relies on).

/// Dot product with eight independent accumulators (vectorises, and the
/// summation order is fixed). Plain multiply-add rather than `mul_add`:
/// without a target FMA feature `mul_add` is a slow library call.
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let mut acc = [0.0f64; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

/// `y -= a * x`.
#[inline]
pub(crate) fn axpy_neg(y: &mut [f64], a: f64, x: &[f64]) {
    debug_assert_eq!(x.len(), y.len());
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi -= a * xi;
    }
}

/// Offset of row `i` in a row-packed lower triangle (row i holds columns 0..=i).
#[inline]
pub(crate) fn row_packed_offset(i: usize) -> usize {
    i * (i + 1) / 2
}

/// Offset of column `j` in a column-packed lower triangle of order `d`
/// (column j holds rows j..d).
#[inline]
pub(crate) fn col_packed_offset(d: usize, j: usize) -> usize {
    j * d - j * j.saturating_sub(1) / 2
}

/// Number of entries in a packed lower triangle of order `n`.
#[inline]
pub(crate) fn packed_len(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Solves `L z = k` in place (`k` becomes `z`) for a row-packed lower `L` of
/// order `k.len()`.
pub(crate) fn forward_solve_row_packed(l: &[f64], k: &mut [f64]) {
    for i in 0..k.len() {
        let off = row_packed_offset(i);
        let row = &l[off..off + i + 1];
        let s = dot(&row[..i], &k[..i]);
        k[i] = (k[i] - s) / row[i];
    }
}

/// Solves `L z = w` in place (`w` becomes `z`) for a column-packed lower `L`
/// of order `w.len()`, streaming the columns once.
pub(crate) fn forward_solve_col_packed(l: &[f64], w: &mut [f64]) {
    let d = w.len();
    let mut off = 0;
    for j in 0..d {
        let col = &l[off..off + (d - j)];
        let zj = w[j] / col[0];
        w[j] = zj;
        axpy_neg(&mut w[j + 1..], zj, &col[1..]);
        off += d - j;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_are_consistent() {
        let d = 7;
        let mut off = 0;
        for j in 0..d {
            assert_eq!(col_packed_offset(d, j), off);
            off += d - j;
        }
        assert_eq!(off, packed_len(d));
        assert_eq!(row_packed_offset(3), 6);
    }

    #[test]
    fn dot_matches_naive() {
        let a: Vec<f64> = (0..19).map(|i| i as f64 * 0.5 - 3.0).collect();
        let b: Vec<f64> = (0..19).map(|i| (i as f64).sin()).collect();
        let naive: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((dot(&a, &b) - naive).abs() < 1e-12);
    }

    #[test]
    fn triangular_solves_invert_the_factor() {
        // L = [[2,0,0],[1,3,0],[-1,0.5,4]]
        let row = [2.0, 1.0, 3.0, -1.0, 0.5, 4.0];
        let col = [2.0, 1.0, -1.0, 3.0, 0.5, 4.0];
        let z = [1.0, -2.0, 0.25];
        let k = [2.0 * z[0], z[0] + 3.0 * z[1], -z[0] + 0.5 * z[1] + 4.0 * z[2]];
        let mut a = k;
        forward_solve_row_packed(&row, &mut a);
        let mut b = k;
        forward_solve_col_packed(&col, &mut b);
        for i in 0..3 {
            assert!((a[i] - z[i]).abs() < 1e-14);
            assert!((b[i] - z[i]).abs() < 1e-14);
        }
    }
}
