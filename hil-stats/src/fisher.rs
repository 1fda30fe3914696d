//! Fisher's exact test of two success counts sharing one rate (a simulated
//! success rate against a published one).

use statrs::function::factorial::ln_binomial;

use crate::error::{Result, StatsError};
use crate::hypothesis::{Alternative, TestResult};

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
/// use hil_stats::{fisher_exact, Alternative};
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
            return Err(StatsError::sample(name, "no trials"));
        }
        if s > n {
            return Err(StatsError::sample(
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
            assert!(matches!(err, StatsError::InvalidSample { .. }), "{err:?}");
        }
    }
}
