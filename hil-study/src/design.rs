//! The conditions of a design, their counterbalanced order per participant,
//! and when queries come within a condition.

use hil_core::{Difficulty, Distraction, ResponseType};
use serde::{Deserialize, Serialize};

use crate::config::{BaselinePosition, DesignConfig, Order};

/// One condition of the design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Condition {
    /// Its id in the study CSV: `c01`, ... for query conditions (in the
    /// order difficulty × distraction × interval), `baseline_<distraction>`.
    pub id: String,
    /// The concurrent distraction task.
    pub distraction: Distraction,
    /// The robot queries, or `None` for a baseline condition.
    pub queries: Option<QueryFactors>,
}

/// The query factors of a query condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct QueryFactors {
    /// Query difficulty.
    pub difficulty: Difficulty,
    /// Minutes between queries.
    pub interval_min: u8,
}

/// A validated design: its conditions and schedule.
///
/// ```
/// use hil_study::{Design, DesignConfig};
/// let d = Design::new(DesignConfig::default()).unwrap();
/// assert_eq!(d.conditions().len(), 14);                  // 12 + 2 baselines
/// assert_eq!(d.query_times_s(0), vec![60.0, 120.0, 180.0, 240.0, 300.0]);
/// let first = d.order(0);
/// assert_eq!(first.len(), 14);
/// assert_ne!(first, d.order(1));                          // counterbalanced
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    config: DesignConfig,
    conditions: Vec<Condition>,
}

impl Design {
    /// Validates `config` and lists its conditions.
    pub fn new(config: DesignConfig) -> hil_core::Result<Self> {
        config.validate()?;
        let mut conditions = Vec::new();
        for &difficulty in &config.difficulties {
            for &distraction in &config.distractions {
                for &interval_min in &config.intervals_min {
                    conditions.push(Condition {
                        id: format!("c{:02}", conditions.len() + 1),
                        distraction,
                        queries: Some(QueryFactors {
                            difficulty,
                            interval_min,
                        }),
                    });
                }
            }
        }
        for &distraction in &config.baselines {
            conditions.push(Condition {
                id: format!("baseline_{}", distraction.as_str()),
                distraction,
                queries: None,
            });
        }
        Ok(Self { config, conditions })
    }

    /// The design's config.
    pub fn config(&self) -> &DesignConfig {
        &self.config
    }

    /// Every condition: the query conditions, then the baselines.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// The condition with id `id`.
    pub fn condition(&self, id: &str) -> Option<(usize, &Condition)> {
        self.conditions.iter().enumerate().find(|(_, c)| c.id == id)
    }

    /// A condition's length in study seconds.
    pub fn duration_s(&self) -> f64 {
        self.config.condition_min * 60.0
    }

    /// Study seconds from the condition start at which its queries come:
    /// from `first_query_min`, every interval, up to the end less
    /// `last_query_margin_min`. Empty for a baseline.
    pub fn query_times_s(&self, condition: usize) -> Vec<f64> {
        let Some(q) = self.conditions[condition].queries else {
            return Vec::new();
        };
        let last = self.duration_s() - self.config.last_query_margin_min * 60.0;
        let step = f64::from(q.interval_min) * 60.0;
        let first = self.config.first_query_min * 60.0;
        (0..)
            .map(|k| first + step * f64::from(k))
            .take_while(|t| *t <= last + 1e-9)
            .collect()
    }

    /// The response type of query `k` of `condition` for participant
    /// number `participant`: the configured types in turn, starting at a
    /// place that shifts with the participant and the condition, so every
    /// type comes first equally often.
    pub fn response_type(&self, participant: usize, condition: usize, k: usize) -> ResponseType {
        let types = &self.config.response_types;
        types[(participant + condition + k) % types.len()]
    }

    /// The order in which participant number `participant` (0-based, in
    /// enrolment order) takes the conditions, as indices into
    /// [`conditions`](Self::conditions): the query conditions in the
    /// counterbalanced order, the baselines first, last or counterbalanced
    /// ([`BaselinePosition`]).
    pub fn order(&self, participant: usize) -> Vec<usize> {
        let n_query = self
            .conditions
            .iter()
            .filter(|c| c.queries.is_some())
            .count();
        let queries: Vec<usize> = match self.config.order {
            Order::Fixed => (0..n_query).collect(),
            Order::BalancedLatinSquare => williams_row(n_query, participant),
        };
        let mut baselines: Vec<usize> = (n_query..self.conditions.len()).collect();
        let first = match self.config.baseline_position {
            BaselinePosition::First => true,
            BaselinePosition::Last => false,
            BaselinePosition::Counterbalanced => {
                if !baselines.is_empty() {
                    let turn = (participant / 2) % baselines.len();
                    baselines.rotate_left(turn);
                }
                participant % 2 == 0
            }
        };
        if first {
            baselines.into_iter().chain(queries).collect()
        } else {
            queries.into_iter().chain(baselines).collect()
        }
    }
}

/// Row `r` of a Williams balanced Latin square of `n` treatments: the
/// first row is 0, 1, n−1, 2, n−2, …; row r adds r (mod n). For odd n the
/// square needs 2n rows, the second n being the first n reversed.
pub fn williams_row(n: usize, r: usize) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let first: Vec<usize> = (0..n)
        .map(|j| {
            if j == 0 {
                0
            } else if j % 2 == 1 {
                j.div_ceil(2)
            } else {
                n - j / 2
            }
        })
        .collect();
    let rows = if n % 2 == 0 { n } else { 2 * n };
    let r = r % rows;
    let mut row: Vec<usize> = first.iter().map(|&f| (f + r % n) % n).collect();
    if r >= n {
        row.reverse();
    }
    row
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every treatment once per row and column; for even n, every ordered
    /// pair of neighbours exactly once over the square (twice for odd n).
    #[test]
    fn williams_squares_are_balanced() {
        for n in 1..=13 {
            let rows = if n % 2 == 0 { n } else { 2 * n };
            let square: Vec<Vec<usize>> = (0..rows).map(|r| williams_row(n, r)).collect();
            let mut pairs = vec![vec![0usize; n]; n];
            for row in &square {
                let mut seen = row.clone();
                seen.sort();
                assert_eq!(seen, (0..n).collect::<Vec<_>>(), "n = {n}");
                for w in row.windows(2) {
                    pairs[w[0]][w[1]] += 1;
                }
            }
            let want = if n % 2 == 0 { 1 } else { 2 };
            for (a, row) in pairs.iter().enumerate() {
                for (b, &c) in row.iter().enumerate() {
                    if a != b && n > 1 {
                        assert_eq!(c, want, "n = {n}: {a} -> {b}");
                    }
                }
            }
            for col in 0..n {
                let mut seen: Vec<usize> = square[..n.max(1)].iter().map(|r| r[col]).collect();
                seen.sort();
                assert_eq!(seen, (0..n).collect::<Vec<_>>(), "n = {n}, column {col}");
            }
        }
    }

    /// The default design reproduces the schedule of the synthetic study.
    #[test]
    fn default_schedule_is_the_synthetic_studys() {
        let d = Design::new(DesignConfig::default()).unwrap();
        for (i, c) in d.conditions().iter().enumerate() {
            match c.queries {
                Some(q) => assert_eq!(
                    d.query_times_s(i),
                    hil_workload::synth::query_times(q.interval_min),
                    "{}",
                    c.id
                ),
                None => assert!(d.query_times_s(i).is_empty()),
            }
        }
        assert_eq!(d.duration_s(), hil_workload::synth::CONDITION_SECONDS);
        assert_eq!(d.conditions()[12].id, "baseline_easy");
        assert_eq!(d.order(5)[..2], [12, 13]);
    }

    /// Counterbalanced baselines: over four participants, each comes
    /// first and last, before and after the other, once each; the query
    /// conditions keep their Latin-square rows.
    #[test]
    fn counterbalanced_baselines_take_every_place() {
        let d = Design::new(DesignConfig {
            baseline_position: BaselinePosition::Counterbalanced,
            ..DesignConfig::default()
        })
        .unwrap();
        let (easy, hard) = (12, 13);
        let placed: Vec<(bool, Vec<usize>)> = (0..4)
            .map(|p| {
                let order = d.order(p);
                let queries: Vec<usize> = order.iter().copied().filter(|&c| c < 12).collect();
                assert_eq!(queries, williams_row(12, p), "participant {p}");
                let first = order[0] >= 12;
                let block = if first { &order[..2] } else { &order[12..] };
                (first, block.to_vec())
            })
            .collect();
        assert_eq!(
            placed,
            vec![
                (true, vec![easy, hard]),
                (false, vec![easy, hard]),
                (true, vec![hard, easy]),
                (false, vec![hard, easy]),
            ]
        );
    }
}
