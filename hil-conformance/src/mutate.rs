//! Mutations of valid inputs, for property tests of parsers: every parser
//! of a user-supplied file must turn whatever these produce into a value
//! or an error naming the file, never a panic or an abort.
//!
//! A mutated input is a valid one with one or more edits applied in turn:
//! truncation, bit flips, inserted or substituted junk (binary bytes,
//! quotes, separators, byte-order marks, deep nesting), a number replaced
//! by a huge, tiny or non-finite one, and a repeated span.
//!
//! ```
//! use proptest::prelude::*;
//! use proptest::test_runner::{Config, TestRunner};
//! use hil_conformance::mutate::mutated;
//! let mut runner = TestRunner::new(Config { cases: 32, ..Config::default() });
//! runner
//!     .run(&mutated(b"a,b\n1,2.5\n".to_vec(), 3), |bytes| {
//!         // A parser under test would run here; this one only decodes.
//!         let _ = String::from_utf8_lossy(&bytes);
//!         Ok(())
//!     })
//!     .unwrap();
//! ```

use proptest::prelude::*;

/// Text that breaks parsers: numbers out of range or not finite, quotes,
/// separators, control characters, a byte-order mark, brackets.
pub const JUNK: &[&str] = &[
    "1e309",
    "-1e309",
    "1e-400",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-0",
    "-1",
    "0",
    "18446744073709551616",
    "99999999999999999999999999999999",
    "4294967296",
    "0x1f",
    "1_000",
    "",
    "\"",
    "\"\"",
    "'",
    ",",
    ",,,,",
    ":",
    "=",
    "\n",
    "\r\n",
    "\r",
    "\0",
    "\u{feff}",
    "{",
    "}",
    "[",
    "]",
    "(",
    ")",
    "é",
    "\u{fffd}",
    "#",
];

/// A position in an input, as a fraction of its length: `k` is at
/// `k / 2^64` of the way through, so one value serves any length.
pub type Pos = u64;

/// Position `p` in a sequence of `len` (`0..len`; 0 when `len` is 0).
fn scale(p: Pos, len: usize) -> usize {
    ((u128::from(p) * len as u128) >> 64) as usize
}

/// One edit of an input.
#[derive(Clone, Debug)]
pub enum Mutation {
    /// Keep only the bytes before this position.
    Truncate(Pos),
    /// Flip bit `1` (0..8) of the byte at `0`.
    FlipBit(Pos, u8),
    /// Insert these bytes at this position.
    Insert(Pos, Vec<u8>),
    /// Replace up to `1` bytes at `0` by `2`.
    Replace(Pos, usize, Vec<u8>),
    /// Replace one of the input's numbers (a run of digits, signs, dots and
    /// exponents) by these bytes.
    Number(Pos, Vec<u8>),
    /// Repeat up to `1` bytes at `0`, `2` more times.
    Repeat(Pos, usize, usize),
}

/// Junk bytes: an entry of [`JUNK`], random bytes, or deep nesting.
pub fn junk() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        4 => proptest::sample::select(JUNK).prop_map(|s| s.as_bytes().to_vec()),
        2 => proptest::collection::vec(any::<u8>(), 1..24),
        1 => (proptest::sample::select(&["[", "{", "(", "\""][..]), 100..3000usize)
            .prop_map(|(s, n)| s.repeat(n).into_bytes()),
    ]
}

/// Any one [`Mutation`].
pub fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<u64>().prop_map(Mutation::Truncate),
        (any::<u64>(), 0..8u8).prop_map(|(i, b)| Mutation::FlipBit(i, b)),
        (any::<u64>(), junk()).prop_map(|(i, j)| Mutation::Insert(i, j)),
        (any::<u64>(), 1..8usize, junk()).prop_map(|(i, n, j)| Mutation::Replace(i, n, j)),
        (any::<u64>(), junk()).prop_map(|(i, j)| Mutation::Number(i, j)),
        (any::<u64>(), 1..64usize, 1..50usize).prop_map(|(i, n, k)| Mutation::Repeat(i, n, k)),
    ]
}

impl Mutation {
    /// Applies the edit to `bytes`.
    pub fn apply(&self, bytes: &mut Vec<u8>) {
        // Positions are taken in 0..=len, so an empty input can grow too.
        let at = |i: &Pos, len: usize| scale(*i, len + 1);
        match self {
            Self::Truncate(i) => {
                let n = at(i, bytes.len());
                bytes.truncate(n);
            }
            Self::FlipBit(i, bit) => {
                if !bytes.is_empty() {
                    let k = scale(*i, bytes.len());
                    bytes[k] ^= 1 << bit;
                }
            }
            Self::Insert(i, junk) => {
                let k = at(i, bytes.len());
                bytes.splice(k..k, junk.iter().copied());
            }
            Self::Replace(i, n, junk) => {
                let k = at(i, bytes.len());
                let end = (k + n).min(bytes.len());
                bytes.splice(k..end, junk.iter().copied());
            }
            Self::Number(i, junk) => {
                let numbers = number_spans(bytes);
                if !numbers.is_empty() {
                    let (s, e) = numbers[scale(*i, numbers.len())];
                    bytes.splice(s..e, junk.iter().copied());
                }
            }
            Self::Repeat(i, n, times) => {
                let k = at(i, bytes.len());
                let end = (k + n).min(bytes.len());
                let span = bytes[k..end].to_vec();
                for _ in 0..*times {
                    bytes.splice(end..end, span.iter().copied());
                }
            }
        }
    }
}

/// The (start, end) byte spans of the numbers in `bytes`: runs that start
/// with a digit (or a sign or dot before one) and continue over digits,
/// dots, signs and `e`/`E`.
fn number_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let mut s = i;
            while s > 0 && matches!(bytes[s - 1], b'-' | b'+' | b'.') {
                s -= 1;
            }
            let mut e = i;
            while e < bytes.len()
                && (bytes[e].is_ascii_digit()
                    || matches!(bytes[e], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                e += 1;
            }
            out.push((s, e));
            i = e;
        } else {
            i += 1;
        }
    }
    out
}

/// `base` with 1..=`max_mutations` mutations applied in turn.
pub fn mutated(base: Vec<u8>, max_mutations: usize) -> impl Strategy<Value = Vec<u8>> {
    proptest::collection::vec(mutation(), 1..=max_mutations.max(1)).prop_map(move |ms| {
        let mut b = base.clone();
        for m in &ms {
            m.apply(&mut b);
        }
        b
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found_with_their_signs_and_exponents() {
        let spans = number_spans(b"a,-1.5e-3,x2,(3, 4)");
        let text: Vec<&str> = spans
            .iter()
            .map(|&(s, e)| std::str::from_utf8(&b"a,-1.5e-3,x2,(3, 4)"[s..e]).unwrap())
            .collect();
        assert_eq!(text, ["-1.5e-3", "2", "3", "4"]);
    }

    #[test]
    fn edits_do_what_they_say() {
        let mut b = b"12,34".to_vec();
        Mutation::Number(0, b"NaN".to_vec()).apply(&mut b);
        assert_eq!(b, b"NaN,34");
        let mut b = b"abc".to_vec();
        Mutation::Truncate(0).apply(&mut b);
        assert!(b.is_empty());
        let mut b = b"ab".to_vec();
        Mutation::Repeat(0, 1, 3).apply(&mut b);
        assert_eq!(b, b"aaaab");
    }
}
