//! Binomial counts: probabilities, upper tails, the standard error of a
//! rate, and the distribution of a sum of independent counts.

/// Probabilities of 0..=n successes in n trials at rate p.
///
/// The coefficient is built up as k grows (n choose k by products, not
/// factorials), exact in floating point for the trial counts used here.
///
/// ```
/// let pmf = hil_stats::binomial_pmf(2, 0.5);
/// assert_eq!(pmf, vec![0.25, 0.5, 0.25]);
/// ```
pub fn binomial_pmf(n: usize, p: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(n + 1);
    let mut c = 1.0; // n choose k, built up as k grows
    for k in 0..=n {
        if k > 0 {
            c *= (n - k + 1) as f64 / k as f64;
        }
        out.push(c * p.powi(k as i32) * (1.0 - p).powi((n - k) as i32));
    }
    out
}

/// P(X ≥ k) for X binomial(n, p), at most 1 (the summed probabilities may
/// exceed it by rounding); 0 when k > n.
///
/// ```
/// assert_eq!(hil_stats::binomial_upper_tail(2, 0.5, 1), 0.75);
/// assert_eq!(hil_stats::binomial_upper_tail(2, 0.5, 0), 1.0);
/// assert_eq!(hil_stats::binomial_upper_tail(2, 0.5, 3), 0.0);
/// ```
pub fn binomial_upper_tail(n: usize, p: f64, k: usize) -> f64 {
    binomial_pmf(n, p)
        .get(k..)
        .map_or(0.0, |tail| tail.iter().sum::<f64>())
        .min(1.0)
}

/// Binomial standard error √(p(1 − p)/n) of the rate of `successes` in
/// `trials`; 0 without trials.
///
/// ```
/// assert_eq!(hil_stats::binomial_se(1, 4), (0.25f64 * 0.75 / 4.0).sqrt());
/// assert_eq!(hil_stats::binomial_se(0, 0), 0.0);
/// ```
pub fn binomial_se(successes: usize, trials: usize) -> f64 {
    if trials == 0 {
        return 0.0;
    }
    let p = successes as f64 / trials as f64;
    (p * (1.0 - p) / trials as f64).sqrt()
}

/// The distribution of the sum of two independent counts, given the
/// distribution of each (probabilities of 0, 1, ...). Both must be
/// non-empty.
///
/// ```
/// // Two fair coins' heads: 0, 1 or 2.
/// let one = hil_stats::binomial_pmf(1, 0.5);
/// assert_eq!(hil_stats::convolve(&one, &one), hil_stats::binomial_pmf(2, 0.5));
/// ```
pub fn convolve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; (a.len() + b.len()).saturating_sub(1)];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pmf_sums_to_one_and_matches_the_closed_form() {
        let pmf = binomial_pmf(30, 0.35);
        assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let choose =
            |n: u64, k: u64| -> f64 { (0..k).map(|i| (n - i) as f64 / (i + 1) as f64).product() };
        for (k, p) in pmf.iter().enumerate() {
            let expect =
                choose(30, k as u64) * 0.35f64.powi(k as i32) * 0.65f64.powi(30 - k as i32);
            assert!((p - expect).abs() < 1e-15, "{k}: {p} vs {expect}");
        }
    }

    #[test]
    fn upper_tail_is_the_summed_pmf() {
        let pmf = binomial_pmf(18, 0.05);
        for k in 0..=18 {
            let expect = pmf[k..].iter().sum::<f64>().min(1.0);
            assert_eq!(binomial_upper_tail(18, 0.05, k), expect);
        }
    }

    #[test]
    fn convolution_of_binomials_is_binomial() {
        let sum = convolve(&binomial_pmf(10, 0.3), &binomial_pmf(20, 0.3));
        for (a, b) in sum.iter().zip(binomial_pmf(30, 0.3)) {
            assert!((a - b).abs() < 1e-14);
        }
        assert!(convolve(&[], &[]).is_empty());
    }
}
