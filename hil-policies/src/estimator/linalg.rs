//! Small streaming kernels over packed triangular storage.
//!
//! The per-step cost of the estimator is memory traffic, so these loops are
//! written to stream their matrices once, front to back, with fixed
//! accumulation orders (results are bit-reproducible run to run, which the
//! checkpoint replay relies on).

#[cfg(target_arch = "x86_64")]
mod multirow;

/// Dot product with eight independent accumulators and a fixed summation
/// order (bit-reproducible on a given machine).
///
/// On x86-64 with AVX2 and FMA (detected at run time) the same loop is
/// compiled with those features, which roughly halves the cost of the
/// compute-bound kernel-form products.
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU supports the features `dot_avx2` is compiled for.
        return unsafe { dot_avx2(a, b) };
    }
    dot_portable(a, b)
}

macro_rules! dot_body {
    ($a:expr, $b:expr, $fma:expr) => {{
        let (a, b) = ($a, $b);
        let mut acc = [0.0f64; 8];
        let ca = a.chunks_exact(8);
        let cb = b.chunks_exact(8);
        let (ra, rb) = (ca.remainder(), cb.remainder());
        for (x, y) in ca.zip(cb) {
            for k in 0..8 {
                acc[k] = $fma(x[k], y[k], acc[k]);
            }
        }
        let mut tail = 0.0;
        for (x, y) in ra.iter().zip(rb) {
            tail = $fma(*x, *y, tail);
        }
        ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
    }};
}

/// Multiply-add as two roundings: without a target FMA feature `mul_add`
/// would be a slow library call.
#[inline(always)]
fn mul_add_plain(x: f64, y: f64, acc: f64) -> f64 {
    acc + x * y
}

fn dot_portable(a: &[f64], b: &[f64]) -> f64 {
    dot_body!(a, b, mul_add_plain)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) fn dot_avx2(a: &[f64], b: &[f64]) -> f64 {
    dot_body!(a, b, f64::mul_add)
}

/// `out[i] = dot(row i of rows, x)` for rows of `x.len()` numbers laid end
/// to end, each bit-identical to [`dot`] of that row (same accumulators,
/// same order).
///
/// Several rows are taken at once, so that each chunk of `x` is loaded once
/// for all of them and their independent accumulators keep the FMA units
/// busy: one [`dot`] per row waits on its 8 accumulators' latency and
/// streams the rows at about half the machine's read bandwidth.
pub(crate) fn dot_rows(rows: &[f64], x: &[f64], out: &mut Vec<f64>) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU supports the features `dot_rows_avx2` is compiled for.
        return unsafe { multirow::dot_rows_avx2(rows, x, out) };
    }
    dot_rows_portable(rows, x, out)
}

/// The scan without target features: four rows at a time (the portable
/// build has no fused multiply-add, so the loop is bound by its adds).
fn dot_rows_portable(rows: &[f64], x: &[f64], out: &mut Vec<f64>) {
    let d = x.len();
    let mut blocks = rows.chunks_exact(4 * d);
    for block in &mut blocks {
        let (r0, rest) = block.split_at(d);
        let (r1, rest) = rest.split_at(d);
        let (r2, r3) = rest.split_at(d);
        let mut acc = [[0.0f64; 8]; 4];
        let n8 = d / 8 * 8;
        let chunks = x
            .chunks_exact(8)
            .zip(r0.chunks_exact(8))
            .zip(r1.chunks_exact(8))
            .zip(r2.chunks_exact(8))
            .zip(r3.chunks_exact(8));
        for ((((xc, c0), c1), c2), c3) in chunks {
            for k in 0..8 {
                acc[0][k] = mul_add_plain(c0[k], xc[k], acc[0][k]);
                acc[1][k] = mul_add_plain(c1[k], xc[k], acc[1][k]);
                acc[2][k] = mul_add_plain(c2[k], xc[k], acc[2][k]);
                acc[3][k] = mul_add_plain(c3[k], xc[k], acc[3][k]);
            }
        }
        for (a, r) in acc.iter().zip([r0, r1, r2, r3]) {
            let mut tail = 0.0;
            for (p, q) in r[n8..].iter().zip(&x[n8..]) {
                tail = mul_add_plain(*p, *q, tail);
            }
            out.push(((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7])) + tail);
        }
    }
    for r in blocks.remainder().chunks_exact(d) {
        out.push(dot_portable(r, x));
    }
}

/// Whether the AVX2 + FMA variants can run here.
#[inline]
pub(crate) fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
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
/// order `k.len()`: z_i = (k_i − dot(L_i,0..i, z_0..i)) / L_ii, with [`dot`]'s
/// arithmetic (the AVX2 variant solves eight rows at a time, with the same
/// numbers).
pub(crate) fn forward_solve_row_packed(l: &[f64], k: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU supports the features the variant is compiled for.
        return unsafe { multirow::forward_solve_row_packed_avx2(l, k) };
    }
    forward_solve_row_packed_by_rows(l, k)
}

/// [`forward_solve_row_packed`] one row at a time.
fn forward_solve_row_packed_by_rows(l: &[f64], k: &mut [f64]) {
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
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU supports the features the variant is compiled for.
        return unsafe { forward_solve_col_packed_avx2(l, w) };
    }
    forward_solve_col_packed_portable(l, w)
}

macro_rules! forward_solve_col_body {
    ($l:expr, $w:expr) => {{
        let (l, w): (&[f64], &mut [f64]) = ($l, $w);
        let d = w.len();
        let mut off = 0;
        for j in 0..d {
            let col = &l[off..off + (d - j)];
            let zj = w[j] / col[0];
            w[j] = zj;
            for (wi, li) in w[j + 1..].iter_mut().zip(&col[1..]) {
                *wi -= zj * li;
            }
            off += d - j;
        }
    }};
}

fn forward_solve_col_packed_portable(l: &[f64], w: &mut [f64]) {
    forward_solve_col_body!(l, w)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn forward_solve_col_packed_avx2(l: &[f64], w: &mut [f64]) {
    forward_solve_col_body!(l, w)
}

/// One fused pass over a column-packed lower factor `l` of order d:
/// replaces L by the Cholesky factor of LLᵀ + wwᵀ (`w` is consumed), and
/// solves the new L·c = v into `c` (`v` is consumed) column by column while
/// each column is in cache.
pub(crate) fn rank_one_update_col_packed(
    l: &mut [f64],
    w: &mut [f64],
    v: &mut [f64],
    c: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU supports the features the variant is compiled for.
        return unsafe { rank_one_update_avx2(l, w, v, c) };
    }
    rank_one_update_portable(l, w, v, c)
}

macro_rules! rank_one_body {
    ($l:expr, $w:expr, $v:expr, $c:expr) => {{
        let (l, w, v, c): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]) = ($l, $w, $v, $c);
        let d = w.len();
        let mut off = 0;
        for j in 0..d {
            let col = &mut l[off..off + (d - j)];
            let (ljj, wj) = (col[0], w[j]);
            let r = (ljj * ljj + wj * wj).sqrt();
            // Rotation taking (ljj, wj) to (r, 0); r ≥ ljj > 0.
            let (cs, sn) = (r / ljj, wj / ljj);
            let inv_cs = ljj / r;
            col[0] = r;
            let cj = v[j] / r;
            c[j] = cj;
            let tail = col[1..]
                .iter_mut()
                .zip(&mut w[j + 1..])
                .zip(&mut v[j + 1..]);
            for ((lij, wi), vi) in tail {
                let nl = (*lij + sn * *wi) * inv_cs;
                *wi = cs * *wi - sn * nl;
                *vi -= cj * nl;
                *lij = nl;
            }
            off += d - j;
        }
    }};
}

fn rank_one_update_portable(l: &mut [f64], w: &mut [f64], v: &mut [f64], c: &mut [f64]) {
    rank_one_body!(l, w, v, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn rank_one_update_avx2(l: &mut [f64], w: &mut [f64], v: &mut [f64], c: &mut [f64]) {
    rank_one_body!(l, w, v, c)
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
    fn dot_rows_is_dot_of_each_row_bit_for_bit() {
        for d in [1, 7, 8, 13, 64, 2048] {
            for n in [0, 1, 3, 4, 5, 8, 9, 17, 23] {
                let rows: Vec<f64> = (0..n * d)
                    .map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0)
                    .collect();
                let x: Vec<f64> = (0..d)
                    .map(|i| ((i * 13 % 29) as f64 - 14.0) / 3.0)
                    .collect();
                let mut out = vec![99.0];
                out.clear();
                dot_rows(&rows, &x, &mut out);
                assert_eq!(out.len(), n);
                for (i, got) in out.iter().enumerate() {
                    let want = dot(&rows[i * d..(i + 1) * d], &x);
                    assert_eq!(got.to_bits(), want.to_bits(), "d {d} n {n} row {i}");
                }
                let mut portable = Vec::new();
                dot_rows_portable(&rows, &x, &mut portable);
                for (i, got) in portable.iter().enumerate() {
                    let want = dot_portable(&rows[i * d..(i + 1) * d], &x);
                    assert_eq!(
                        got.to_bits(),
                        want.to_bits(),
                        "portable d {d} n {n} row {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn blocked_forward_solve_is_the_row_by_row_solve_bit_for_bit() {
        for n in [0, 1, 7, 8, 9, 16, 23, 300] {
            // A well-conditioned lower factor: unit-scale entries, a
            // dominant diagonal.
            let l: Vec<f64> = (0..packed_len(n))
                .map(|p| ((p * 37 % 101) as f64 - 50.0) / 500.0)
                .collect();
            let mut l = l;
            for i in 0..n {
                l[row_packed_offset(i) + i] = 2.0 + (i % 5) as f64;
            }
            let k: Vec<f64> = (0..n)
                .map(|i| ((i * 13 % 29) as f64 - 14.0) / 3.0)
                .collect();
            let (mut blocked, mut by_rows) = (k.clone(), k.clone());
            forward_solve_row_packed(&l, &mut blocked);
            forward_solve_row_packed_by_rows(&l, &mut by_rows);
            for i in 0..n {
                assert_eq!(blocked[i].to_bits(), by_rows[i].to_bits(), "n {n} row {i}");
            }
        }
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
        let k = [
            2.0 * z[0],
            z[0] + 3.0 * z[1],
            -z[0] + 0.5 * z[1] + 4.0 * z[2],
        ];
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
