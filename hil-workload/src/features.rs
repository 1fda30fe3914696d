//! Feature encoding on the Δt grid.
//!
//! Each query is one-hot encoded as 8 numbers: difficulty (easy, hard),
//! response type (mcq, bounding box, open-ended), distraction (none, easy,
//! hard). A Granger model with history H sees, for each lag i in 0..H, the
//! encoding of the query asked at timestep t − i (summed if several), and
//! zeros where no query was asked or the history runs out.
//!
//! Design columns: `[WL_0, 1, lag 0 (8), lag 1 (8), …]`, so the design for
//! a shorter history is a prefix of the design for a longer one.

use hil_core::{QueryHistory, QueryKind, Timestep};

use crate::datasets::TrainingPair;

/// Numbers per query in the one-hot encoding.
pub const KIND_FEATURES: usize = 8;
/// Columns before the lag features: WL_0 and the bias.
pub const LEAD_COLUMNS: usize = 2;

/// Names of the 8 one-hot features, in order.
pub const KIND_FEATURE_NAMES: [&str; KIND_FEATURES] = [
    "difficulty_easy",
    "difficulty_hard",
    "response_mcq",
    "response_bounding_box",
    "response_open_ended",
    "distraction_none",
    "distraction_easy",
    "distraction_hard",
];

/// The indices of the three ones of `kind`'s encoding.
///
/// ```
/// use hil_core::QueryKind;
/// assert_eq!(hil_workload::features::one_hot_indices(&QueryKind::default()), [0, 2, 5]);
/// ```
pub fn one_hot_indices(kind: &QueryKind) -> [usize; 3] {
    [
        kind.difficulty as usize,
        2 + kind.response as usize,
        5 + kind.distraction as usize,
    ]
}

/// Number of design columns for history `h`.
pub fn n_columns(h: usize) -> usize {
    LEAD_COLUMNS + KIND_FEATURES * h
}

/// The sparse lag features of `history` at `t` for history length `h`:
/// (column, value) pairs, columns counted from the first lag column.
pub fn lag_features(history: &QueryHistory, t: Timestep, h: usize) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64)> = Vec::new();
    for (lag, r) in history.recent(t, h as u64) {
        for j in one_hot_indices(&r.kind) {
            let c = lag as usize * KIND_FEATURES + j;
            match out.iter_mut().find(|(cc, _)| *cc == c) {
                Some(e) => e.1 += 1.0,
                None => out.push((c, 1.0)),
            }
        }
    }
    out
}

/// One sparse design row: `[WL_0, 1, lags…]` for history `h`, plus target.
#[derive(Clone, Debug, PartialEq)]
pub struct SparseRow {
    /// (column, value) entries, columns in design order.
    pub entries: Vec<(usize, f64)>,
    /// The target workload.
    pub y: f64,
}

impl SparseRow {
    /// Encodes `pair` for history length `h`.
    ///
    /// Costs O(h + log n) for a pair whose history holds n queries: only
    /// the queries of the last `h` timesteps are read.
    pub fn of_pair(pair: &TrainingPair, h: usize) -> Self {
        let records = pair.history.records();
        // The history is in time order, so the queries inside the window are
        // a tail of it; `lag_features` then reads them as any model would.
        let start = records.partition_point(|r| pair.t.saturating_sub(r.t) >= h as u64);
        let window = QueryHistory::from_records(records[start..].to_vec())
            .expect("a slice of a valid history is valid");
        let mut entries = vec![(0, pair.wl0), (1, 1.0)];
        entries.extend(
            lag_features(&window, pair.t, h)
                .into_iter()
                .map(|(c, v)| (c + LEAD_COLUMNS, v)),
        );
        Self {
            entries,
            y: pair.target,
        }
    }

    /// The row restricted to the first `k` columns, dotted with `w`.
    pub fn dot_prefix(&self, w: &[f64]) -> f64 {
        self.entries
            .iter()
            .filter(|(c, _)| *c < w.len())
            .map(|(c, v)| v * w[*c])
            .sum()
    }
}
