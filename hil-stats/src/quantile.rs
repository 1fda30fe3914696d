//! Medians and quantiles.

/// The median of `xs` (the mean of the middle two for an even count);
/// NaN when empty. Values are ordered by [`f64::total_cmp`].
///
/// ```
/// assert_eq!(hil_stats::median(&[3.0, 1.0, 2.0]), 2.0);
/// assert_eq!(hil_stats::median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
/// assert!(hil_stats::median(&[]).is_nan());
/// ```
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The `q`-quantile of `xs` by nearest rank: the value at position
/// round((n − 1)·q) of the sorted sample, without interpolation (so
/// `quantile(xs, 0.5)` is the upper of the two middle values for an even
/// count, where [`median`] averages them). `q` is clamped to [0, 1]; NaN
/// when `xs` is empty.
///
/// ```
/// let xs = [5.0, 1.0, 4.0, 2.0, 3.0, 6.0];
/// assert_eq!(hil_stats::quantile(&xs, 0.0), 1.0);
/// assert_eq!(hil_stats::quantile(&xs, 0.1), 2.0); // round(0.5) = 1
/// assert_eq!(hil_stats::quantile(&xs, 0.5), 4.0);
/// assert_eq!(hil_stats::quantile(&xs, 1.0), 6.0);
/// assert!(hil_stats::quantile(&[], 0.5).is_nan());
/// ```
pub fn quantile(xs: &[f64], q: f64) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_middle_quantile_is_the_upper_median() {
        for n in 1..12 {
            let xs: Vec<f64> = (0..n).rev().map(f64::from).collect();
            let mut sorted = xs.clone();
            sorted.sort_by(f64::total_cmp);
            assert_eq!(quantile(&xs, 0.5), sorted[sorted.len() / 2], "n = {n}");
            if n % 2 == 1 {
                assert_eq!(quantile(&xs, 0.5), median(&xs));
            }
        }
    }
}
