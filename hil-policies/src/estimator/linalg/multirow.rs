//! AVX2 kernels that run [`dot`](super::dot) over several rows at once.
//!
//! One [`super::dot`] waits on the latency of its eight accumulators and
//! streams a row at about half the machine's read bandwidth. Taking
//! several rows together loads each chunk of the shared vector once for
//! all of them, and their independent accumulators keep the FMA units busy.
//! Each row keeps `dot`'s eight accumulators, as two 4-lane vectors, and
//! its reduction order, so every result is bit-identical to `dot` of that
//! row (the tests check it).
//!
//! Written with intrinsics: the plain loop over four rows, compiled for
//! AVX2, was vectorised across the rows (one lane per row) and spent its
//! time shuffling.

use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_setzero_pd, _mm256_storeu_pd,
};

use super::{dot_avx2, row_packed_offset};

/// Rows per block. Eight rows keep eight read streams in flight, which the
/// hardware prefetchers serve at the full read bandwidth (four reached
/// about 0.8 of it on an AMD EPYC); their 16 accumulator vectors fit the
/// 16 AVX2 registers.
const ROWS: usize = 8;

/// For each row, `dot`'s accumulators over `x` (whose length is a multiple
/// of 8, the part `dot` handles in chunks) folded in pairs:
/// `a[k] = acc[k] + acc[k + 4]`.
#[target_feature(enable = "avx2,fma")]
fn lane_sums<const R: usize>(rows: [&[f64]; R], x: &[f64]) -> [[f64; 4]; R] {
    let m = x.len();
    assert!(m % 8 == 0 && rows.iter().all(|r| r.len() >= m));
    let mut lo: [__m256d; R] = [_mm256_setzero_pd(); R];
    let mut hi: [__m256d; R] = [_mm256_setzero_pd(); R];
    let ptrs = rows.map(<[f64]>::as_ptr);
    let xp = x.as_ptr();
    for j in (0..m).step_by(8) {
        // SAFETY: j + 8 ≤ m, and x and every row hold at least m numbers
        // (asserted above), so every load is in bounds.
        unsafe {
            let xl = _mm256_loadu_pd(xp.add(j));
            let xh = _mm256_loadu_pd(xp.add(j + 4));
            for r in 0..R {
                let rp = ptrs[r].add(j);
                lo[r] = _mm256_fmadd_pd(_mm256_loadu_pd(rp), xl, lo[r]);
                hi[r] = _mm256_fmadd_pd(_mm256_loadu_pd(rp.add(4)), xh, hi[r]);
            }
        }
    }
    let mut out = [[0.0; 4]; R];
    for (a, (l, h)) in out.iter_mut().zip(lo.iter().zip(&hi)) {
        // SAFETY: `a` holds the 4 numbers stored.
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), _mm256_add_pd(*l, *h)) };
    }
    out
}

/// `dot`'s result from its folded accumulators and the sequential sum of
/// the elements past the last whole chunk.
#[inline(always)]
fn finish(a: [f64; 4], tail: f64) -> f64 {
    ((a[0] + a[1]) + (a[2] + a[3])) + tail
}

/// The fused multiply-add sum `dot` gives the elements past its last chunk.
#[target_feature(enable = "avx2,fma")]
fn tail_sum(a: &[f64], b: &[f64]) -> f64 {
    let mut tail = 0.0;
    for (p, q) in a.iter().zip(b) {
        tail = p.mul_add(*q, tail);
    }
    tail
}

/// `out[i] = dot(row i, x)` for rows of `x.len()` numbers laid end to end.
#[target_feature(enable = "avx2,fma")]
pub(super) fn dot_rows_avx2(rows: &[f64], x: &[f64], out: &mut Vec<f64>) {
    let d = x.len();
    let n8 = d / 8 * 8;
    let mut blocks = rows.chunks_exact(ROWS * d);
    for block in &mut blocks {
        let row = |r: usize| &block[r * d..(r + 1) * d];
        let sums = lane_sums::<ROWS>(std::array::from_fn(row), &x[..n8]);
        for (r, a) in sums.into_iter().enumerate() {
            out.push(finish(a, tail_sum(&row(r)[n8..], &x[n8..])));
        }
    }
    for r in blocks.remainder().chunks_exact(d) {
        out.push(dot_avx2(r, x));
    }
}

/// Solves `L z = k` in place for a row-packed lower `L`, eight rows at a
/// time. Rows i0..i0 + 8 (i0 a multiple of 8) are `dot`s whose chunked
/// part is the same, columns 0..i0, where z is already known: those run
/// together; the few columns past i0 are finished row by row.
#[target_feature(enable = "avx2,fma")]
pub(super) fn forward_solve_row_packed_avx2(l: &[f64], k: &mut [f64]) {
    let n = k.len();
    let row = |i: usize| &l[row_packed_offset(i)..row_packed_offset(i) + i + 1];
    let mut i0 = 0;
    while i0 + ROWS <= n {
        let sums = lane_sums::<ROWS>(std::array::from_fn(|r| row(i0 + r)), &k[..i0]);
        for (r, a) in sums.into_iter().enumerate() {
            let (i, li) = (i0 + r, row(i0 + r));
            let s = finish(a, tail_sum(&li[i0..i], &k[i0..i]));
            k[i] = (k[i] - s) / li[i];
        }
        i0 += ROWS;
    }
    for i in i0..n {
        let li = row(i);
        let s = dot_avx2(&li[..i], &k[..i]);
        k[i] = (k[i] - s) / li[i];
    }
}
