//! Summaries of a sample: mean, population standard deviation and the
//! standard error of the mean, as the paper and every results file report
//! them.
//!
//! The arithmetic is fixed on purpose: the mean is the sum in order over n
//! and the standard deviation the population one (over n); the published
//! results files are reproduced bit for bit from it.

use serde::{Deserialize, Serialize};

/// The mean of `xs`: their sum, in order, over their count; NaN when empty.
///
/// ```
/// assert_eq!(hil_stats::mean(&[1.0, 2.0, 6.0]), 3.0);
/// assert!(hil_stats::mean(&[]).is_nan());
/// ```
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// Mean and (population) standard deviation of a sample, as the paper
/// reports; both NaN when empty.
///
/// ```
/// let (m, s) = hil_stats::mean_std(&[1.0, 3.0]);
/// assert_eq!((m, s), (2.0, 1.0));
/// ```
pub fn mean_std(xs: &[f64]) -> (f64, f64) {
    if xs.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n;
    (m, v.sqrt())
}

/// The standard error of the mean of `xs`: the sample standard deviation
/// over √n, that is the population one of [`mean_std`] over √(n − 1).
/// `None` with fewer than two values, where it is undefined.
///
/// ```
/// assert_eq!(hil_stats::standard_error(&[1.0, 3.0]), Some(1.0));
/// assert_eq!(hil_stats::standard_error(&[5.0]), None);
/// ```
pub fn standard_error(xs: &[f64]) -> Option<f64> {
    let (_, std) = mean_std(xs);
    (xs.len() >= 2).then(|| std / (xs.len() as f64 - 1.0).sqrt())
}

/// Mean, population standard deviation (what the paper's ± reports) and
/// standard error of the mean of a sample.
///
/// Serialised as `{mean, std, se}` (the results files' format; `n` is left
/// out so that those files keep their shape). Where a file reports a mean
/// with its standard error only, as `{mean, sem}` with `sem` null below two
/// values, use the [`as_mean_sem`] adapter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Mean.
    pub mean: f64,
    /// Population standard deviation.
    pub std: f64,
    /// Standard error of the mean ([`standard_error`]; 0 for fewer than
    /// two values).
    pub se: f64,
    /// Number of values summarised. Not serialised: 0 when read back from
    /// a `{mean, std, se}` file.
    #[serde(skip_serializing, default)]
    pub n: usize,
}

impl Stat {
    /// The statistics of `xs`.
    ///
    /// ```
    /// let s = hil_stats::Stat::of(&[1.0, 2.0, 3.0]);
    /// assert_eq!((s.mean, s.std, s.n), (2.0, (2.0f64 / 3.0).sqrt(), 3));
    /// assert!((s.se - 1.0 / 3f64.sqrt()).abs() < 1e-12);
    /// ```
    pub fn of(xs: &[f64]) -> Self {
        let (mean, std) = mean_std(xs);
        Self {
            mean,
            std,
            se: standard_error(xs).unwrap_or(0.0),
            n: xs.len(),
        }
    }

    /// The standard error where it is defined (two values or more), else
    /// `None`.
    ///
    /// ```
    /// assert_eq!(hil_stats::Stat::of(&[1.0, 3.0]).sem(), Some(1.0));
    /// assert_eq!(hil_stats::Stat::of(&[5.0]).sem(), None);
    /// ```
    pub fn sem(&self) -> Option<f64> {
        (self.n >= 2).then_some(self.se)
    }
}

/// Serde adapter writing a [`Stat`] as `{mean, sem}`, `sem` null with
/// fewer than two values ([`Stat::sem`]): the format of files that report
/// a mean with its standard error only. Use it as
/// `#[serde(with = "hil_stats::summary::as_mean_sem")]` on a `Stat`, or its
/// [`seq`](as_mean_sem::seq) and [`map`](as_mean_sem::map) on a `Vec<Stat>`
/// or a `BTreeMap<String, Stat>`.
///
/// The format holds no standard deviation and no count: read back, `std`
/// is NaN and `n` is 2 when `sem` is given (the least count that defines
/// it), else 1, so that writing the value again gives the same text.
///
/// ```
/// use hil_stats::Stat;
/// #[derive(serde::Serialize, serde::Deserialize)]
/// struct Row {
///     #[serde(with = "hil_stats::summary::as_mean_sem")]
///     figure: Stat,
/// }
/// let text = serde_json::to_string(&Row { figure: Stat::of(&[1.0, 3.0]) }).unwrap();
/// assert_eq!(text, r#"{"figure":{"mean":2.0,"sem":1.0}}"#);
/// let one = serde_json::to_string(&Row { figure: Stat::of(&[5.0]) }).unwrap();
/// assert_eq!(one, r#"{"figure":{"mean":5.0,"sem":null}}"#);
/// let back: Row = serde_json::from_str(&text).unwrap();
/// assert_eq!(back.figure.sem(), Some(1.0));
/// ```
pub mod as_mean_sem {
    use std::collections::BTreeMap;

    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::Stat;

    /// The written form.
    #[derive(Serialize, Deserialize)]
    struct MeanSem {
        mean: f64,
        sem: Option<f64>,
    }

    impl From<&Stat> for MeanSem {
        fn from(s: &Stat) -> Self {
            MeanSem {
                mean: s.mean,
                sem: s.sem(),
            }
        }
    }

    impl From<MeanSem> for Stat {
        fn from(m: MeanSem) -> Self {
            Stat {
                mean: m.mean,
                std: f64::NAN,
                se: m.sem.unwrap_or(0.0),
                n: if m.sem.is_some() { 2 } else { 1 },
            }
        }
    }

    /// Writes one `Stat` as `{mean, sem}`.
    pub fn serialize<S: Serializer>(stat: &Stat, s: S) -> Result<S::Ok, S::Error> {
        MeanSem::from(stat).serialize(s)
    }

    /// Reads one `Stat` from `{mean, sem}`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Stat, D::Error> {
        MeanSem::deserialize(d).map(Stat::from)
    }

    /// The adapter for a `Vec<Stat>`.
    pub mod seq {
        use super::*;

        /// Writes each `Stat` as `{mean, sem}`.
        pub fn serialize<S: Serializer>(stats: &[Stat], s: S) -> Result<S::Ok, S::Error> {
            s.collect_seq(stats.iter().map(MeanSem::from))
        }

        /// Reads a list of `{mean, sem}`.
        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Stat>, D::Error> {
            let v = Vec::<MeanSem>::deserialize(d)?;
            Ok(v.into_iter().map(Stat::from).collect())
        }
    }

    /// The adapter for a `BTreeMap<String, Stat>`.
    pub mod map {
        use super::*;

        /// Writes each `Stat` as `{mean, sem}` under its key.
        pub fn serialize<S: Serializer>(
            stats: &BTreeMap<String, Stat>,
            s: S,
        ) -> Result<S::Ok, S::Error> {
            s.collect_map(stats.iter().map(|(k, v)| (k, MeanSem::from(v))))
        }

        /// Reads a map of `{mean, sem}`.
        pub fn deserialize<'de, D: Deserializer<'de>>(
            d: D,
        ) -> Result<BTreeMap<String, Stat>, D::Error> {
            let m = BTreeMap::<String, MeanSem>::deserialize(d)?;
            Ok(m.into_iter().map(|(k, v)| (k, Stat::from(v))).collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_writes_mean_std_se_and_reads_them_back() {
        let s = Stat::of(&[1.0, 2.0, 4.0]);
        let text = serde_json::to_string(&s).unwrap();
        assert!(
            text.starts_with(r#"{"mean":"#) && !text.contains("\"n\""),
            "{text}"
        );
        let back: Stat = serde_json::from_str(&text).unwrap();
        assert_eq!(
            (back.mean, back.std, back.se, back.n),
            (s.mean, s.std, s.se, 0)
        );
    }

    #[test]
    fn empty_and_single_samples() {
        let e = Stat::of(&[]);
        assert!(e.mean.is_nan() && e.std.is_nan());
        assert_eq!((e.se, e.n, e.sem()), (0.0, 0, None));
        // A constant sample has a defined standard error of 0.
        assert_eq!(Stat::of(&[2.0, 2.0, 2.0]).sem(), Some(0.0));
    }

    #[test]
    fn mean_sem_format_round_trips() {
        #[derive(Serialize, Deserialize)]
        struct Rows {
            #[serde(with = "as_mean_sem::seq")]
            list: Vec<Stat>,
            #[serde(with = "as_mean_sem::map")]
            by: std::collections::BTreeMap<String, Stat>,
        }
        let rows = Rows {
            list: vec![Stat::of(&[1.0]), Stat::of(&[0.0, 0.0])],
            by: [("a".to_string(), Stat::of(&[1.0, 2.0]))].into(),
        };
        let text = serde_json::to_string(&rows).unwrap();
        assert_eq!(
            text,
            r#"{"list":[{"mean":1.0,"sem":null},{"mean":0.0,"sem":0.0}],"by":{"a":{"mean":1.5,"sem":0.5}}}"#
        );
        let back: Rows = serde_json::from_str(&text).unwrap();
        assert_eq!(serde_json::to_string(&back).unwrap(), text);
    }
}
