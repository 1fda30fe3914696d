//! proptest strategies for hil's vocabulary.

use proptest::prelude::*;

use hil_core::{
    Context, Difficulty, Distraction, QueryHistory, QueryKind, QueryRecord, ResponseType,
};

/// Finite contexts of dimension `dim` with entries in [-scale, scale].
pub fn context(dim: usize, scale: f64) -> impl Strategy<Value = Context> {
    proptest::collection::vec(-scale..=scale, dim)
        .prop_map(|v| Context::new(v).expect("finite by construction"))
}

/// Any query kind.
pub fn query_kind() -> impl Strategy<Value = QueryKind> {
    (0..3usize, 0..2usize, 0..3usize).prop_map(|(r, d, x)| QueryKind {
        response: ResponseType::ALL[r],
        difficulty: Difficulty::ALL[d],
        distraction: Distraction::ALL[x],
    })
}

/// Query histories of up to `max_len` queries at times in 1..=`max_t`,
/// sorted (several queries may share a timestep).
pub fn query_history(max_len: usize, max_t: u64) -> impl Strategy<Value = QueryHistory> {
    proptest::collection::vec((1..=max_t.max(1), query_kind()), 0..=max_len).prop_map(|mut v| {
        v.sort_by_key(|(t, _)| *t);
        QueryHistory::from_records(
            v.into_iter()
                .map(|(t, kind)| QueryRecord { t, kind })
                .collect(),
        )
        .expect("sorted by construction")
    })
}

/// Symmetric positive-definite `n × n` matrices (row-major), built as
/// `BᵀB + eps·I` with entries of B in [-1, 1].
pub fn spd_matrix(n: usize, eps: f64) -> impl Strategy<Value = Vec<f64>> {
    proptest::collection::vec(-1.0f64..1.0, n * n).prop_map(move |b| {
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += b[k * n + i] * b[k * n + j];
                }
                a[i * n + j] = s + if i == j { eps } else { 0.0 };
            }
        }
        a
    })
}
