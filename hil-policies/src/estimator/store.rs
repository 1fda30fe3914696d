//! A deduplicated, contiguous store of context rows.
//!
//! Kernel-form arms keep their observations as indices into one store shared
//! by all arms, so a context seen for several arms (a dataset that labels
//! each context with every action, or repeated attempts at one item) is
//! stored and scanned once per decision.

use std::collections::HashMap;

/// Rows of length `dim`, each stored once (bitwise equality).
#[derive(Clone, Debug)]
pub(crate) struct RowStore {
    dim: usize,
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
            data: Vec::new(),
            index: HashMap::new(),
        }
    }

    /// Number of distinct rows.
    pub(crate) fn len(&self) -> usize {
        self.data.len() / self.dim
    }

    pub(crate) fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// The index of `x`, inserting it if new.
    pub(crate) fn insert(&mut self, x: &[f64]) -> u32 {
        let h = hash_bits(x);
        if let Some(cands) = self.index.get(&h) {
            for &c in cands {
                if same_bits(self.row(c as usize), x) {
                    return c;
                }
            }
        }
        let i = self.len() as u32;
        self.data.extend_from_slice(x);
        self.index.entry(h).or_default().push(i);
        i
    }

    /// `out[i] = row(i) · x` for every row: one streaming pass over the store.
    pub(crate) fn products(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            self.data
                .chunks_exact(self.dim)
                .map(|r| super::linalg::dot(r, x)),
        );
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

    /// Bytes of row data.
    pub(crate) fn bytes(&self) -> usize {
        self.data.len() * std::mem::size_of::<f64>()
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
}
