//! Corrections of p-values for the number of tests made.

/// The Bonferroni-adjusted p-value of one of `tests` tests: `p · tests`,
/// at most 1. Applied to the smallest p-value of a family, it bounds the
/// chance that any test of the family comes out that small when every null
/// hypothesis holds.
///
/// ```
/// assert_eq!(hil_stats::bonferroni(0.125, 4), 0.5);
/// assert_eq!(hil_stats::bonferroni(0.2, 18), 1.0);
/// ```
pub fn bonferroni(p: f64, tests: usize) -> f64 {
    (p * tests as f64).min(1.0)
}
