//! Rank tests used in the paper: one-sided Mann-Whitney U between
//! populations and the Wilcoxon signed-rank test for paired comparisons;
//! and Fisher's exact test of two success counts sharing one rate (a
//! simulated success rate against a published one).
//!
//! Small samples without ties use exact null distributions; otherwise the
//! normal approximation with tie and continuity corrections (the usual
//! large-sample method). Normal tail probabilities come from `statrs`.

use hil_core::{HilError, Result};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal};
use statrs::function::factorial::ln_binomial;

/// The alternative hypothesis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Alternative {
    /// The first sample is stochastically smaller (or differences < 0).
    Less,
    /// The first sample is stochastically greater (or differences > 0).
    Greater,
    /// Either direction.
    TwoSided,
}

/// A test statistic and its p-value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestResult {
    /// U of the first sample (Mann-Whitney) or W+ (Wilcoxon).
    pub statistic: f64,
    /// The p-value under the chosen alternative.
    pub p_value: f64,
    /// True if the exact null distribution was used.
    pub exact: bool,
}

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

fn check(name: &str, xs: &[f64]) -> Result<()> {
    if xs.is_empty() {
        return Err(HilError::invalid_input(name, "empty sample"));
    }
    if let Some(x) = xs.iter().find(|x| !x.is_finite()) {
        return Err(HilError::invalid_input(name, format!("{x} is not finite")));
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
/// use hil_workload::stats::{mann_whitney_u, Alternative};
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

/// Fisher's exact test that `successes_a` of `trials_a` and `successes_b`
/// of `trials_b` come from one success rate: conditional on the total
/// successes, the first count is hypergeometric. `Less` asks whether the
/// first sample's rate is lower; `TwoSided` sums the probabilities of every
/// count no more likely than the one observed (R's `fisher.test`), with a
/// relative allowance of 10⁻⁷ so that ties in floating point count as ties.
/// The statistic is `successes_a`; the test is exact, and conservative as
/// every test on counts is.
///
/// ```
/// use hil_workload::stats::{fisher_exact, Alternative};
/// // Fisher's tea taster: 3 of 4 cups right against 1 of 4.
/// let r = fisher_exact(3, 4, 1, 4, Alternative::Greater).unwrap();
/// assert!((r.p_value - 17.0 / 70.0).abs() < 1e-12);
/// let two = fisher_exact(3, 4, 1, 4, Alternative::TwoSided).unwrap();
/// assert!((two.p_value - 34.0 / 70.0).abs() < 1e-12);
/// ```
pub fn fisher_exact(
    successes_a: u64,
    trials_a: u64,
    successes_b: u64,
    trials_b: u64,
    alt: Alternative,
) -> Result<TestResult> {
    for (name, s, n) in [
        ("first sample", successes_a, trials_a),
        ("second sample", successes_b, trials_b),
    ] {
        if n == 0 {
            return Err(HilError::invalid_input(name, "no trials"));
        }
        if s > n {
            return Err(HilError::invalid_input(
                name,
                format!("{s} successes in {n} trials"),
            ));
        }
    }
    let total = successes_a + successes_b;
    let lo = total.saturating_sub(trials_b);
    let hi = total.min(trials_a);
    let ln_all = ln_binomial(trials_a + trials_b, total);
    let pmf = |x: u64| (ln_binomial(trials_a, x) + ln_binomial(trials_b, total - x) - ln_all).exp();
    let observed = pmf(successes_a);
    let (mut p_le, mut p_ge, mut p_two) = (0.0, 0.0, 0.0);
    for x in lo..=hi {
        let p = pmf(x);
        if x <= successes_a {
            p_le += p;
        }
        if x >= successes_a {
            p_ge += p;
        }
        if p <= observed * (1.0 + 1e-7) {
            p_two += p;
        }
    }
    let p_value = match alt {
        Alternative::Less => p_le,
        Alternative::Greater => p_ge,
        Alternative::TwoSided => p_two,
    };
    Ok(TestResult {
        statistic: successes_a as f64,
        p_value: p_value.min(1.0),
        exact: true,
    })
}

/// Wilcoxon signed-rank test on the differences `x − y` (zeros dropped).
///
/// ```
/// use hil_workload::stats::{wilcoxon_signed_rank, Alternative};
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
        return Err(HilError::invalid_input(
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
        return Err(HilError::invalid_input(
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
    fn fisher_exact_matches_enumerated_tables() {
        // 0 of 30 against 53 of 960: the two-sided p-value sums the
        // hypergeometric tables no likelier than the observed one; checked
        // here against a direct product of binomial coefficients.
        let r = fisher_exact(0, 30, 53, 960, Alternative::TwoSided).unwrap();
        let choose =
            |n: u64, k: u64| -> f64 { (0..k).map(|i| (n - i) as f64 / (i + 1) as f64).product() };
        let all = choose(990, 53);
        let p = |x: u64| choose(30, x) * choose(960, 53 - x) / all;
        let expect: f64 = (0..=30).map(p).filter(|&q| q <= p(0) * (1.0 + 1e-7)).sum();
        assert!(
            (r.p_value - expect).abs() < 1e-9,
            "{} vs {expect}",
            r.p_value
        );
        assert!(r.p_value > 0.3 && r.p_value < 0.5, "{r:?}");
        // Identical rates: nothing is less likely than the mode's neighbours.
        let same = fisher_exact(10, 20, 10, 20, Alternative::TwoSided).unwrap();
        assert!((same.p_value - 1.0).abs() < 1e-12);
        // One-sided tails add up to 1 plus the observed table's probability.
        let le = fisher_exact(2, 10, 7, 10, Alternative::Less).unwrap();
        let ge = fisher_exact(2, 10, 7, 10, Alternative::Greater).unwrap();
        assert!((le.p_value + ge.p_value - 1.0 - p_of(2, 10, 7, 10)).abs() < 1e-12);
        assert!(le.p_value < 0.05 && ge.p_value > 0.95);
    }

    fn p_of(a: u64, n1: u64, b: u64, n2: u64) -> f64 {
        (ln_binomial(n1, a) + ln_binomial(n2, b) - ln_binomial(n1 + n2, a + b)).exp()
    }

    #[test]
    fn fisher_exact_rejects_impossible_counts() {
        for (a, n1, b, n2) in [(3, 2, 0, 5), (0, 5, 6, 5), (0, 0, 1, 5), (1, 5, 0, 0)] {
            let err = fisher_exact(a, n1, b, n2, Alternative::TwoSided).unwrap_err();
            assert!(matches!(err, HilError::InvalidInput { .. }), "{err:?}");
        }
    }

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
