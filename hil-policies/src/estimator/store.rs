//! A deduplicated, contiguous store of context rows.
//!
//! Kernel-form arms keep their observations as indices into one store shared
//! by all arms, so a context seen for several arms (a dataset that labels
//! each context with every action, or repeated attempts at one item) is
//! stored and scanned once per decision.
//!
//! **Frozen rows.** After pretraining, the rows so far are frozen into an
//! `Arc` that clones share: a pretrained estimator is cloned for every
//! episode of a protocol, and copying thousands of 2048-d rows each time
//! was a fifth of `hil reproduce`'s time. The frozen part also memoises the
//! products of a context with its rows (bounded: [`MEMO_LIMIT`] contexts),
//! since replayed datasets present the same contexts in many episodes. The
//! memoised numbers are the ones a scan computes, bit for bit, so results
//! and checkpoint replay do not depend on it.

use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Mutex};

use super::linalg;

/// Most context hashes whose products with the frozen rows are memoised; beyond
/// it, products are computed every time (a live robot sees new contexts
/// forever, and memory must stay bounded).
pub(crate) const MEMO_LIMIT: usize = 4096;

/// Most hashes of contexts seen once that are remembered (8 bytes each);
/// beyond it the set starts over, so a context recurring only after this
/// many others is not memoised.
const SEEN_LIMIT: usize = 1 << 16;

/// hash of x → (x, products of x with every frozen row).
type ProductMemo = HashMap<u64, Vec<(Arc<[f64]>, Arc<[f64]>)>>;

/// The memoised products, and the hashes of contexts seen once (the
/// candidates for memoising).
#[derive(Debug, Default)]
struct Memo {
    products: ProductMemo,
    seen_once: HashSet<u64>,
}

/// Rows shared by clones, with the memo of their products.
#[derive(Debug, Default)]
struct Frozen {
    data: Vec<f64>,
    index: HashMap<u64, Vec<u32>>,
    memo: Mutex<Memo>,
}

/// Rows of length `dim`, each stored once (bitwise equality): the frozen
/// rows first, then the rows added since.
#[derive(Clone, Debug)]
pub(crate) struct RowStore {
    dim: usize,
    frozen: Arc<Frozen>,
    data: Vec<f64>,
    index: HashMap<u64, Vec<u32>>,
}

fn hash_bits(x: &[f64]) -> u64 {
    // FNV-1a over the bit patterns: cheap next to the O(d) work that follows.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in x {
        h ^= v.to_bits();
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

impl RowStore {
    pub(crate) fn new(dim: usize) -> Self {
        Self {
            dim,
            frozen: Arc::default(),
            data: Vec::new(),
            index: HashMap::new(),
        }
    }

    fn frozen_len(&self) -> usize {
        self.frozen.data.len() / self.dim
    }

    /// Number of distinct rows.
    pub(crate) fn len(&self) -> usize {
        self.frozen_len() + self.data.len() / self.dim
    }

    pub(crate) fn row(&self, i: usize) -> &[f64] {
        let f = self.frozen_len();
        if i < f {
            &self.frozen.data[i * self.dim..(i + 1) * self.dim]
        } else {
            let i = i - f;
            &self.data[i * self.dim..(i + 1) * self.dim]
        }
    }

    /// The index of `x`, inserting it if new.
    pub(crate) fn insert(&mut self, x: &[f64]) -> u32 {
        let h = hash_bits(x);
        for index in [&self.frozen.index, &self.index] {
            if let Some(cands) = index.get(&h) {
                for &c in cands {
                    if same_bits(self.row(c as usize), x) {
                        return c;
                    }
                }
            }
        }
        let i = self.len() as u32;
        self.data.extend_from_slice(x);
        self.index.entry(h).or_default().push(i);
        i
    }

    /// Moves every row into the frozen part that clones share (and starts a
    /// new memo). Row indices do not change.
    pub(crate) fn freeze(&mut self) {
        if self.data.is_empty() {
            return;
        }
        let mut data = self.frozen.data.clone();
        let mut index = self.frozen.index.clone();
        data.append(&mut self.data);
        for (h, rows) in self.index.drain() {
            index.entry(h).or_default().extend(rows);
        }
        self.frozen = Arc::new(Frozen {
            data,
            index,
            memo: Mutex::default(),
        });
    }

    /// `out[i] = row(i) · x` for every row: one streaming pass over the store
    /// (the frozen rows' part memoised per context).
    pub(crate) fn products(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if !self.frozen.data.is_empty() {
            let h = hash_bits(x);
            let mut memo = self.memo_lock();
            let hit = memo.products.get(&h).and_then(|c| {
                c.iter()
                    .find(|(k, _)| same_bits(k, x))
                    .map(|(_, g)| g.clone())
            });
            match hit {
                Some(g) => {
                    drop(memo);
                    out.extend_from_slice(&g);
                }
                None => {
                    // Only a context seen before is kept: a live robot's
                    // contexts are all new, and copying each one (16 KB at
                    // d = 2048) with its products into the memo cost more
                    // than the memo saved. Replayed contexts pay one extra
                    // scan, on their second sight.
                    let keep = memo.products.len() < MEMO_LIMIT && !memo.seen_once.insert(h);
                    if memo.seen_once.len() >= SEEN_LIMIT {
                        memo.seen_once.clear();
                    }
                    drop(memo);
                    linalg::dot_rows(&self.frozen.data, x, out);
                    if keep {
                        let g: Arc<[f64]> = out.as_slice().into();
                        let mut memo = self.memo_lock();
                        // Counting hashes, not entries: collisions are rare,
                        // and summing the buckets would cost O(memo).
                        if memo.products.len() < MEMO_LIMIT {
                            memo.products.entry(h).or_default().push((x.into(), g));
                        }
                    }
                }
            }
        }
        linalg::dot_rows(&self.data, x, out);
    }

    fn memo_lock(&self) -> std::sync::MutexGuard<'_, Memo> {
        // A panic while the lock was held can only have left a memo entry
        // out, never a wrong one (entries are pushed whole).
        self.frozen
            .memo
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Keeps only the rows for which `keep` is true, returning the old → new
    /// index map (`u32::MAX` for dropped rows).
    pub(crate) fn compact(&mut self, keep: &[bool]) -> Vec<u32> {
        let mut fresh = RowStore::new(self.dim);
        let mut map = vec![u32::MAX; self.len()];
        for (i, k) in keep.iter().enumerate() {
            if *k {
                map[i] = fresh.insert(self.row(i));
            }
        }
        *self = fresh;
        map
    }

    /// Bytes of row data (the frozen rows included, though clones share them).
    pub(crate) fn bytes(&self) -> usize {
        (self.frozen.data.len() + self.data.len()) * std::mem::size_of::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deduplicates_and_compacts() {
        let mut s = RowStore::new(2);
        assert_eq!(s.insert(&[1.0, 2.0]), 0);
        assert_eq!(s.insert(&[3.0, 4.0]), 1);
        assert_eq!(s.insert(&[1.0, 2.0]), 0);
        assert_eq!(s.len(), 2);
        let mut out = Vec::new();
        s.products(&[1.0, 1.0], &mut out);
        assert_eq!(out, vec![3.0, 7.0]);
        let map = s.compact(&[false, true]);
        assert_eq!(map, vec![u32::MAX, 0]);
        assert_eq!(s.row(0), &[3.0, 4.0]);
    }

    #[test]
    fn frozen_rows_are_shared_found_and_memoised_exactly() {
        let mut s = RowStore::new(2);
        s.insert(&[1.0, 2.0]);
        s.insert(&[3.0, 4.0]);
        s.freeze();
        let mut c = s.clone();
        assert!(Arc::ptr_eq(&s.frozen, &c.frozen));
        assert_eq!(c.insert(&[3.0, 4.0]), 1, "a frozen row is found");
        assert_eq!(c.insert(&[5.0, 6.0]), 2);
        assert_eq!((c.len(), s.len()), (3, 2));
        assert_eq!(c.row(2), &[5.0, 6.0]);
        let x = [0.5, -1.5];
        let (mut first, mut again) = (Vec::new(), Vec::new());
        c.products(&x, &mut first);
        c.products(&x, &mut again);
        let scan: Vec<f64> = (0..3)
            .map(|i| super::super::linalg::dot(c.row(i), &x))
            .collect();
        assert_eq!(first, scan);
        assert_eq!(again, scan);
        assert_eq!(
            s.memo_lock().products.len(),
            1,
            "seen twice, memoised, and the memo is shared with the original"
        );
        let mut memoised = Vec::new();
        c.products(&x, &mut memoised);
        assert_eq!(memoised, scan, "products read back from the memo");
        // Compaction keeps rows and indices consistent across the two parts.
        let map = c.compact(&[false, true, true]);
        assert_eq!(map, vec![u32::MAX, 0, 1]);
        assert_eq!(c.row(1), &[5.0, 6.0]);
    }

    #[test]
    fn contexts_seen_once_are_not_copied_into_the_memo() {
        let dim = 64;
        let mut s = RowStore::new(dim);
        for i in 0..10 {
            s.insert(&vec![i as f64; dim]);
        }
        s.freeze();
        let mut out = Vec::new();
        for i in 0..100 {
            let x: Vec<f64> = (0..dim).map(|j| (i * dim + j) as f64).collect();
            s.products(&x, &mut out);
            assert_eq!(out.len(), 10);
        }
        let memo = s.memo_lock();
        assert_eq!(memo.products.len(), 0, "fresh contexts are never stored");
        assert_eq!(memo.seen_once.len(), 100, "only their hashes are");
    }
}
