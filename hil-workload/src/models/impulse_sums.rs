//! The decayed impulse sums of Exp-Impulse, carried forward along each
//! condition instead of summed afresh for every pair.
//!
//! For a pair measured at t after queries at t_1 ≤ … ≤ t_c (those of its
//! prefix with t_i ≤ t), feature j is f_j(t) = Σ_i e^(−λ(t − t_i))·[j ∈ q_i].
//! Summed directly that is O(c) per pair, so O(n²) for a condition of n
//! queries, which every λ of the fit's search pays again. The sums obey
//! S_k = S_(k−1)·e^(−λ(t_k − t_(k−1))) + onehot(q_k) and f(t) =
//! S_c·e^(−λ(t − t_c)), so walking a condition's pairs in prefix order
//! ([`by_shared_history`]) costs O(pairs + queries).

use hil_core::Timestep;

use crate::datasets::{TrainingPair, by_shared_history};
use crate::features::{KIND_FEATURES, one_hot_indices};

/// One condition's queries and the pairs measured along it.
#[derive(Debug)]
struct Walk {
    /// (time, one-hot indices) of the queries the group's pairs count.
    queries: Vec<(Timestep, [usize; 3])>,
    /// (pair index, queries counted, measurement time), by queries counted.
    pairs: Vec<(usize, usize, Timestep)>,
}

/// A set of pairs laid out for [`ImpulseSums::features`] at many decay
/// rates (the layout is built once per training set).
#[derive(Debug)]
pub(crate) struct ImpulseSums {
    walks: Vec<Walk>,
    n_pairs: usize,
}

impl ImpulseSums {
    pub(crate) fn new(pairs: &[&TrainingPair]) -> Self {
        let walks = by_shared_history(pairs)
            .into_iter()
            .map(|group| {
                let whole = pairs[group[0]].history.whole().records();
                let pairs: Vec<(usize, usize, Timestep)> = group
                    .iter()
                    .map(|&i| {
                        let p = pairs[i];
                        // The prefix is in time order: the queries at or
                        // before t are a head of it.
                        let counted = p.history.records().partition_point(|r| r.t <= p.t);
                        (i, counted, p.t)
                    })
                    .collect();
                let mut pairs = pairs;
                pairs.sort_by_key(|&(_, c, _)| c);
                let n = pairs.last().map_or(0, |&(_, c, _)| c);
                let queries = whole[..n]
                    .iter()
                    .map(|r| (r.t, one_hot_indices(&r.kind)))
                    .collect();
                Walk { queries, pairs }
            })
            .collect();
        Self {
            walks,
            n_pairs: pairs.len(),
        }
    }

    /// `out[i]` = the decayed impulse sums of pair `i` at decay `lambda`.
    pub(crate) fn features(&self, lambda: f64, out: &mut Vec<[f64; KIND_FEATURES]>) {
        out.clear();
        out.resize(self.n_pairs, [0.0; KIND_FEATURES]);
        for w in &self.walks {
            let mut s = [0.0; KIND_FEATURES];
            let mut added = 0;
            let mut last_t: Timestep = 0;
            for &(i, counted, t) in &w.pairs {
                while added < counted {
                    let (tq, ones) = w.queries[added];
                    let decay = (-lambda * (tq - last_t) as f64).exp();
                    for v in &mut s {
                        *v *= decay;
                    }
                    for j in ones {
                        s[j] += 1.0;
                    }
                    last_t = tq;
                    added += 1;
                }
                if counted > 0 {
                    let decay = (-lambda * (t - last_t) as f64).exp();
                    out[i] = s.map(|v| v * decay);
                }
            }
        }
    }
}

/// The sums of one pair, summed directly (O(queries)); what
/// [`ImpulseSums::features`] must agree with.
#[cfg(test)]
pub(crate) fn direct(p: &TrainingPair, lambda: f64) -> [f64; KIND_FEATURES] {
    let mut f = [0.0; KIND_FEATURES];
    for r in p.history.records().iter().filter(|r| r.t <= p.t) {
        let w = (-lambda * (p.t - r.t) as f64).exp();
        for j in one_hot_indices(&r.kind) {
            f[j] += w;
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use hil_core::{Difficulty, Distraction, QueryHistory, QueryKind, ResponseType};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::datasets::HistoryPrefix;

    /// Conditions of random length with random gaps (repeats of a timestep
    /// included), one pair per query measured a random while after it, in
    /// shuffled order.
    fn random_pairs(rng: &mut ChaCha8Rng) -> Vec<TrainingPair> {
        let mut pairs = Vec::new();
        for _ in 0..rng.random_range(1..6) {
            let mut h = QueryHistory::new();
            let mut t = rng.random_range(0..5u64);
            let n = rng.random_range(0..400);
            for _ in 0..n {
                t += rng.random_range(0..20u64);
                let kind = QueryKind {
                    difficulty: Difficulty::ALL[rng.random_range(0..2)],
                    response: ResponseType::ALL[rng.random_range(0..3)],
                    distraction: Distraction::ALL[rng.random_range(0..3)],
                };
                h.push(t, kind).unwrap();
            }
            let h = Arc::new(h);
            for (k, r) in h.records().iter().enumerate() {
                pairs.push(TrainingPair {
                    participant: 0,
                    wl0: rng.random(),
                    t: r.t + rng.random_range(0..15u64),
                    history: HistoryPrefix::new(Arc::clone(&h), k + 1),
                    target: rng.random(),
                });
            }
            // A pair whose prefix ends after its measurement counts only the
            // queries at or before it.
            if n > 0 {
                pairs.push(TrainingPair {
                    participant: 0,
                    wl0: 0.5,
                    t: h.records()[0].t,
                    history: HistoryPrefix::new(Arc::clone(&h), n),
                    target: 0.5,
                });
            }
        }
        let len = pairs.len();
        for i in (1..len).rev() {
            pairs.swap(i, rng.random_range(0..=i));
        }
        pairs
    }

    #[test]
    fn recursive_sums_equal_the_direct_ones() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        let mut out = Vec::new();
        let mut checked = 0;
        for _ in 0..20 {
            let pairs = random_pairs(&mut rng);
            let refs: Vec<&TrainingPair> = pairs.iter().collect();
            let sums = ImpulseSums::new(&refs);
            for lambda in [0.0, 1e-4, 3e-3, 0.05, 0.7, 10.0] {
                sums.features(lambda, &mut out);
                assert_eq!(out.len(), pairs.len());
                for (p, got) in pairs.iter().zip(&out) {
                    let want = direct(p, lambda);
                    for (g, w) in got.iter().zip(&want) {
                        let tol = 1e-12 * w.abs().max(1.0);
                        assert!((g - w).abs() <= tol, "λ = {lambda}: {got:?} vs {want:?}");
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
    }
}
