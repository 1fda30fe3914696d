//! The formulas that callers wrote inline before they used this crate,
//! compared bit for bit with what replaced them on fixed inputs: the
//! published results files must not change by a single bit.

use hil_stats::{
    Stat, binomial_pmf, binomial_upper_tail, bonferroni, mean, mean_std, median, quantile,
    standard_error,
};

/// Fixed, irregular samples (a linear congruential sequence, no RNG crate).
fn samples() -> Vec<Vec<f64>> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = vec![vec![], vec![0.25], vec![0.0, 0.0], vec![2.0, 2.0, 2.0]];
    for n in [2, 3, 5, 10, 31, 64] {
        out.push((0..n).map(|_| next() * 3.0 - 1.0).collect());
    }
    out
}

#[test]
fn means_equal_an_in_order_sum_over_n_and_a_running_total() {
    for xs in samples().into_iter().filter(|xs| !xs.is_empty()) {
        let inline = xs.iter().sum::<f64>() / xs.len() as f64;
        assert_eq!(mean(&xs).to_bits(), inline.to_bits(), "{xs:?}");
        // `let mut total = 0.0; for x { total += x }; total / n`
        let mut total = 0.0;
        for x in &xs {
            total += x;
        }
        assert_eq!(mean(&xs).to_bits(), (total / xs.len() as f64).to_bits());
    }
}

#[test]
fn mean_and_std_equal_the_selection_tables_inline_formula() {
    for xs in samples() {
        let n = xs.len() as f64;
        let m = xs.iter().sum::<f64>() / n;
        let s = (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
        let (m2, s2) = mean_std(&xs);
        assert!(m.to_bits() == m2.to_bits() || (m.is_nan() && m2.is_nan()));
        assert!(s.to_bits() == s2.to_bits() || (s.is_nan() && s2.is_nan()));
    }
}

/// The user study's former `{mean, sem}` type, as it was written.
#[derive(serde::Serialize)]
struct FormerMeanSem {
    mean: f64,
    sem: Option<f64>,
}

#[test]
fn the_mean_sem_format_is_written_as_before() {
    #[derive(serde::Serialize)]
    struct Now {
        #[serde(with = "hil_stats::summary::as_mean_sem")]
        s: Stat,
    }
    #[derive(serde::Serialize)]
    struct Before {
        s: FormerMeanSem,
    }
    for xs in samples() {
        let before = Before {
            s: FormerMeanSem {
                mean: mean_std(&xs).0,
                sem: standard_error(&xs),
            },
        };
        let now = Now { s: Stat::of(&xs) };
        assert_eq!(
            serde_json::to_string(&now).unwrap(),
            serde_json::to_string(&before).unwrap()
        );
    }
}

#[test]
fn medians_and_quantiles_equal_the_benchmarks_sort_then_index() {
    for xs in samples().into_iter().filter(|xs| !xs.is_empty()) {
        let mut sorted = xs.clone();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let mid = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
        };
        assert_eq!(median(&xs).to_bits(), mid.to_bits());
        for p in [0.0, 0.1, 0.5, 0.9] {
            let pct = sorted[((n - 1) as f64 * p).round() as usize];
            assert_eq!(quantile(&xs, p).to_bits(), pct.to_bits());
        }
        assert_eq!(quantile(&xs, 0.0), sorted[0]);
        assert_eq!(quantile(&xs, 0.5), sorted[n / 2]);
    }
}

#[test]
fn tails_and_corrections_equal_the_calibrations_inline_forms() {
    for cells in 0..=18 {
        for below in 0..=cells {
            let inline = binomial_pmf(cells, 0.05)[below..]
                .iter()
                .sum::<f64>()
                .min(1.0);
            assert_eq!(
                binomial_upper_tail(cells, 0.05, below).to_bits(),
                inline.to_bits()
            );
        }
        for p in [0.0, 1e-4, 0.003, 0.05, 0.2] {
            let inline = (p * cells as f64).min(1.0);
            assert_eq!(bonferroni(p, cells).to_bits(), inline.to_bits());
        }
    }
}
