//! Rank tests used in the paper: one-sided Mann-Whitney U between
//! populations and the Wilcoxon signed-rank test for paired comparisons.
//!
//! Small samples without ties use exact null distributions; otherwise the
//! normal approximation with tie and continuity corrections (the usual
//! large-sample method). Normal tail probabilities come from `statrs`.

use statrs::distribution::{ContinuousCDF, Normal};

use crate::error::{Result, StatsError};
use crate::hypothesis::{Alternative, TestResult};

/// Exact methods are used up to this many observations (no ties).
pub const EXACT_LIMIT: usize = 50;

/// Midranks (1-based) of `v` and the tie correction term Σ(t³ − t).
fn midranks(v: &[f64]) -> (Vec<f64>, f64) {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut ranks = vec![0.0; v.len()];
    let mut ties = 0.0;
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
            j += 1;
        }
        let r = (i + j) as f64 / 2.0 + 1.0;
        for &k in &idx[i..=j] {
            ranks[k] = r;
        }
        let t = (j - i + 1) as f64;
        ties += t * t * t - t;
        i = j + 1;
    }
    (ranks, ties)
}

fn check(name: &'static str, xs: &[f64]) -> Result<()> {
    if xs.is_empty() {
        return Err(StatsError::sample(name, "empty sample"));
    }
    if let Some(x) = xs.iter().find(|x| !x.is_finite()) {
        return Err(StatsError::sample(name, format!("{x} is not finite")));
    }
    Ok(())
}

fn tail(alt: Alternative, p_le: f64, p_ge: f64) -> f64 {
    match alt {
        Alternative::Less => p_le,
        Alternative::Greater => p_ge,
        Alternative::TwoSided => (2.0 * p_le.min(p_ge)).min(1.0),
    }
}

fn normal_p(alt: Alternative, stat: f64, mean: f64, sd: f64) -> f64 {
    let n = Normal::new(0.0, 1.0).expect("standard normal");
    if sd == 0.0 {
        return 1.0;
    }
    // continuity correction of 0.5 toward the mean
    let z_le = (stat - mean + 0.5) / sd;
    let z_ge = (stat - mean - 0.5) / sd;
    tail(alt, n.cdf(z_le), 1.0 - n.cdf(z_ge))
}

/// Mann-Whitney U test of `x` against `y`.
///
/// ```
/// use hil_stats::{mann_whitney_u, Alternative};
/// let r = mann_whitney_u(&[1.0, 2.0, 3.0, 4.0, 5.0], &[6.0, 7.0, 8.0, 9.0, 10.0], Alternative::Less).unwrap();
/// assert_eq!(r.statistic, 0.0);
/// assert!((r.p_value - 1.0 / 252.0).abs() < 1e-12); // one arrangement in C(10, 5)
/// ```
pub fn mann_whitney_u(x: &[f64], y: &[f64], alt: Alternative) -> Result<TestResult> {
    check("first sample", x)?;
    check("second sample", y)?;
    let (n1, n2) = (x.len(), y.len());
    let all: Vec<f64> = x.iter().chain(y).copied().collect();
    let (ranks, ties) = midranks(&all);
    let r1: f64 = ranks[..n1].iter().sum();
    let u = r1 - (n1 * (n1 + 1)) as f64 / 2.0;
    let (f1, f2) = (n1 as f64, n2 as f64);
    if ties == 0.0 && n1 + n2 <= EXACT_LIMIT {
        // counts[u] = arrangements with U = u, by the recursion
        // c(m, n, u) = c(m-1, n, u-n) + c(m, n-1, u)
        let max_u = n1 * n2;
        let mut table = vec![vec![vec![0f64; max_u + 1]; n2 + 1]; n1 + 1];
        for m in 0..=n1 {
            for n in 0..=n2 {
                if m == 0 || n == 0 {
                    table[m][n][0] = 1.0;
                    continue;
                }
                for uu in 0..=m * n {
                    let a = if uu >= n {
                        table[m - 1][n][uu - n]
                    } else {
                        0.0
                    };
                    let b = table[m][n - 1].get(uu).copied().unwrap_or(0.0);
                    table[m][n][uu] = a + b;
                }
            }
        }
        let counts = &table[n1][n2];
        let total: f64 = counts.iter().sum();
        let ui = u.round() as usize;
        let p_le = counts[..=ui].iter().sum::<f64>() / total;
        let p_ge = counts[ui..].iter().sum::<f64>() / total;
        return Ok(TestResult {
            statistic: u,
            p_value: tail(alt, p_le, p_ge),
            exact: true,
        });
    }
    let n = f1 + f2;
    let var = f1 * f2 / 12.0 * ((n + 1.0) - ties / (n * (n - 1.0)));
    Ok(TestResult {
        statistic: u,
        p_value: normal_p(alt, u, f1 * f2 / 2.0, var.max(0.0).sqrt()),
        exact: false,
    })
}

/// Wilcoxon signed-rank test on the differences `x − y` (zeros dropped).
///
/// ```
/// use hil_stats::{wilcoxon_signed_rank, Alternative};
/// let x: Vec<f64> = (1..=10).map(|i| i as f64 + 0.5 * i as f64).collect();
/// let y: Vec<f64> = (1..=10).map(|i| i as f64).collect();
/// let r = wilcoxon_signed_rank(&x, &y, Alternative::Greater).unwrap();
/// assert_eq!(r.statistic, 55.0);
/// assert!((r.p_value - 1.0 / 1024.0).abs() < 1e-12); // all signs positive
/// ```
pub fn wilcoxon_signed_rank(x: &[f64], y: &[f64], alt: Alternative) -> Result<TestResult> {
    check("first sample", x)?;
    check("second sample", y)?;
    if x.len() != y.len() {
        return Err(StatsError::sample(
            "paired samples",
            format!("lengths differ: {} and {}", x.len(), y.len()),
        ));
    }
    let d: Vec<f64> = x
        .iter()
        .zip(y)
        .map(|(a, b)| a - b)
        .filter(|d| *d != 0.0)
        .collect();
    if d.is_empty() {
        return Err(StatsError::sample(
            "paired samples",
            "all differences are zero",
        ));
    }
    let abs: Vec<f64> = d.iter().map(|v| v.abs()).collect();
    let (ranks, ties) = midranks(&abs);
    let w_plus: f64 = ranks
        .iter()
        .zip(&d)
        .filter(|(_, d)| **d > 0.0)
        .map(|(r, _)| r)
        .sum();
    let n = d.len();
    if ties == 0.0 && n <= EXACT_LIMIT {
        let max = n * (n + 1) / 2;
        let mut counts = vec![0f64; max + 1];
        counts[0] = 1.0;
        for k in 1..=n {
            for s in (k..=max).rev() {
                counts[s] += counts[s - k];
            }
        }
        let total: f64 = counts.iter().sum();
        let wi = w_plus.round() as usize;
        let p_le = counts[..=wi].iter().sum::<f64>() / total;
        let p_ge = counts[wi..].iter().sum::<f64>() / total;
        return Ok(TestResult {
            statistic: w_plus,
            p_value: tail(alt, p_le, p_ge),
            exact: true,
        });
    }
    let f = n as f64;
    let mean = f * (f + 1.0) / 4.0;
    let var = f * (f + 1.0) * (2.0 * f + 1.0) / 24.0 - ties / 48.0;
    Ok(TestResult {
        statistic: w_plus,
        p_value: normal_p(alt, w_plus, mean, var.max(0.0).sqrt()),
        exact: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mann_whitney_textbook_values() {
        // Exact: U = 3 for n1 = n2 = 4 has P(U ≤ 3) = 7/70 = 0.1
        // (counts of U = 0, 1, 2, 3 are 1, 1, 2, 3).
        let r = mann_whitney_u(
            &[1.0, 2.0, 3.0, 7.5],
            &[4.0, 5.0, 6.0, 8.0],
            Alternative::Less,
        )
        .unwrap();
        assert_eq!(r.statistic, 3.0);
        assert!((r.p_value - 0.1).abs() < 1e-12, "{r:?}");
        let g = mann_whitney_u(
            &[1.0, 2.0, 3.0, 7.5],
            &[4.0, 5.0, 6.0, 8.0],
            Alternative::Greater,
        )
        .unwrap();
        assert!((g.p_value - (1.0 - 4.0 / 70.0)).abs() < 1e-12, "{g:?}");
        // Large sample with ties: normal approximation, z from first principles.
        let x: Vec<f64> = (0..60).map(|i| (i % 5) as f64).collect();
        let y: Vec<f64> = (0..60).map(|i| (i % 5) as f64 + 1.0).collect();
        let r = mann_whitney_u(&x, &y, Alternative::Less).unwrap();
        assert!(!r.exact && r.p_value < 1e-3, "{r:?}");
        let two = mann_whitney_u(&x, &y, Alternative::TwoSided).unwrap();
        assert!((two.p_value - 2.0 * r.p_value).abs() < 1e-12);
    }

    #[test]
    fn wilcoxon_textbook_values() {
        // n = 5, W+ = 1 (only rank 1 positive): P(W+ ≤ 1) = 2/32.
        let x = [1.0, -2.0, -3.0, -4.0, -5.0];
        let r = wilcoxon_signed_rank(&x, &[0.0; 5], Alternative::Less).unwrap();
        assert_eq!(r.statistic, 1.0);
        assert!((r.p_value - 2.0 / 32.0).abs() < 1e-12, "{r:?}");
        // Exact and normal approximations agree closely for n = 30.
        let d: Vec<f64> = (1..=30)
            .map(|i| if i % 3 == 0 { -(i as f64) } else { i as f64 })
            .collect();
        let exact = wilcoxon_signed_rank(&d, &[0.0; 30], Alternative::Greater).unwrap();
        let mut tied = d.clone();
        tied.push(1.0); // a tie forces the approximation
        let approx = wilcoxon_signed_rank(&tied, &[0.0; 31], Alternative::Greater).unwrap();
        assert!(exact.exact && !approx.exact);
        assert!(
            (exact.p_value - approx.p_value).abs() < 0.02,
            "{exact:?} {approx:?}"
        );
        assert!(wilcoxon_signed_rank(&[1.0], &[1.0], Alternative::Less).is_err());
    }
}
