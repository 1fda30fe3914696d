//! The hash chain that makes a log tamper-evident.
//!
//! Every line of a log starts with a `chain` field: the SHA-256 of the
//! previous line's chain value followed by the line's own content (the
//! record's JSON without the `chain` field). So a changed byte anywhere,
//! a removed or reordered line, or a header spliced from another log breaks
//! the chain, and the check names the line at fault.
//!
//! `resumed` markers are chained *beside* the log, not into it: their digest
//! is computed from the chain value before them (so a damaged marker is
//! still found), but the next line continues from that same value. A
//! resumed session therefore holds byte for byte the lines an uninterrupted
//! run writes, plus its markers.
//!
//! Unkeyed, the digest is SHA-256: it detects corruption and edits made by
//! hand or by a tool that does not know the format, not a forger who
//! recomputes it. A keyed chain ([`Chain::start_keyed`]) uses HMAC-SHA256
//! with a secret [`RecordKey`] over the same bytes, so only a holder of the
//! key can produce a chain that verifies; its digests are compared in
//! constant time, and a failed check never tells what the digest should
//! have been.
//!
//! ```
//! use hil_record::chain::{Chain, split};
//! let mut chain = Chain::start();
//! let line = chain.seal(r#"{"record":"episode_start","episode":0,"seed":1}"#, true);
//! let (digest, content) = split(&line).unwrap();
//! assert_eq!(content, r#"{"record":"episode_start","episode":0,"seed":1}"#);
//! assert_eq!(digest, chain.hex());
//! ```

use std::sync::Arc;

use hmac::{Hmac, Mac};
use sha2::{Digest, Sha256};

use super::key::RecordKey;

type HmacSha256 = Hmac<Sha256>;

/// The name of the field every line starts with.
pub const FIELD: &str = "chain";

/// What every line starts with, up to the hex digest.
const PREFIX: &str = "{\"chain\":\"";
/// Hex digits of a SHA-256 digest.
const HEX_LEN: usize = 64;

/// The running value of a log's chain, and its key if it is keyed.
#[derive(Clone, Debug)]
pub struct Chain {
    value: [u8; 32],
    key: Option<Arc<RecordKey>>,
}

impl PartialEq for Chain {
    /// Equal values (the key is implied by the values it produced).
    fn eq(&self, other: &Self) -> bool {
        self.value == other.value
    }
}

impl Chain {
    /// The value before the first line: the digest of the format's name, so
    /// that a chain of some other format never continues into this one.
    pub fn start() -> Self {
        Self {
            value: Sha256::digest(super::format::FORMAT_NAME.as_bytes()).into(),
            key: None,
        }
    }

    /// The same start, for a chain keyed with `key` (HMAC-SHA256).
    pub fn start_keyed(key: RecordKey) -> Self {
        Self {
            key: Some(Arc::new(key)),
            ..Self::start()
        }
    }

    /// The key, if the chain is keyed.
    pub fn key(&self) -> Option<&RecordKey> {
        self.key.as_deref()
    }

    /// The MAC (keyed) of the previous value and `content`, still open.
    fn mac(&self, key: &RecordKey, content: &str) -> HmacSha256 {
        // HMAC takes a key of any length: this never fails.
        let mut mac = HmacSha256::new_from_slice(key.bytes()).expect("HMAC takes any key length");
        mac.update(&self.value);
        mac.update(content.as_bytes());
        mac
    }

    /// The chain value of a line with `content` that follows `self`.
    fn next(&self, content: &str) -> Self {
        let value = match &self.key {
            None => {
                let mut h = Sha256::new();
                h.update(self.value);
                h.update(content.as_bytes());
                h.finalize().into()
            }
            Some(key) => self.mac(key, content).finalize().into_bytes().into(),
        };
        Self {
            value,
            key: self.key.clone(),
        }
    }

    /// The value as lower-case hex.
    pub fn hex(&self) -> String {
        hex(&self.value)
    }

    /// The full line for `content` (a JSON object): `content` with the chain
    /// field first. With `advance`, the chain moves on to this line;
    /// without (a `resumed` marker), it stays where it was.
    pub fn seal(&mut self, content: &str, advance: bool) -> String {
        let next = self.next(content);
        let line = format!(
            "{PREFIX}{}\",{}",
            next.hex(),
            content.strip_prefix('{').unwrap_or(content)
        );
        if advance {
            *self = next;
        }
        line
    }

    /// Checks a line's stated digest against the chain and the line's
    /// content; on success, moves on (if `advance`). On failure, the chain
    /// is unchanged and the error says what the digest should have been.
    pub fn check(&mut self, stated: &str, content: &str, advance: bool) -> Result<(), String> {
        if let Some(key) = &self.key {
            return self.check_keyed(&key.clone(), stated, content, advance);
        }
        let next = self.next(content);
        if next.hex() != stated {
            return Err(format!(
                "the line's digest is {stated} but the previous lines and its content give {}: \
                 this line (or one before it) was changed after it was written, or lines were \
                 removed, reordered or taken from another log",
                next.hex()
            ));
        }
        if advance {
            *self = next;
        }
        Ok(())
    }

    /// [`Chain::check`] of a keyed chain: the MAC is compared in constant
    /// time, and the error does not say what it should have been (that
    /// would hand a forger the MAC of his edit).
    fn check_keyed(
        &mut self,
        key: &RecordKey,
        stated: &str,
        content: &str,
        advance: bool,
    ) -> Result<(), String> {
        let stated_bytes = from_hex(stated).unwrap_or_default();
        let mac = self.mac(key, content);
        let value: [u8; 32] = mac.clone().finalize().into_bytes().into();
        if mac.verify_slice(&stated_bytes).is_err() {
            return Err(format!(
                "the line's HMAC does not verify with the key in {}: this line (or one before \
                 it) was changed after it was written, lines were removed, reordered or taken \
                 from another log, or the log was chained with another key or none",
                key.path().display()
            ));
        }
        if advance {
            self.value = value;
        }
        Ok(())
    }
}

/// Splits a line into its stated digest and its content (the record's JSON
/// without the chain field). `None` if the line does not start with a
/// well-formed chain field.
pub fn split(line: &str) -> Option<(&str, String)> {
    let rest = line.strip_prefix(PREFIX)?;
    let digest = rest.get(..HEX_LEN)?;
    if !digest
        .bytes()
        .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    {
        return None;
    }
    let body = rest[HEX_LEN..].strip_prefix("\",")?;
    Some((digest, format!("{{{body}")))
}

/// SHA-256 of `text`, as lower-case hex (the header's `config_digest`).
pub fn digest_hex(text: &str) -> String {
    hex(&Sha256::digest(text.as_bytes()))
}

/// Lower-case hex of `bytes`.
pub(crate) fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write;
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// The bytes a hex string (lower- or upper-case) spells, if it does.
pub(crate) fn from_hex(text: &str) -> Option<Vec<u8>> {
    if text.is_empty() || text.len() % 2 != 0 || !text.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(text.get(i..i + 2)?, 16).ok())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sealed_line_checks_and_any_changed_byte_does_not() {
        let content = r#"{"record":"outcome","episode":0,"t":3}"#;
        let mut writer = Chain::start();
        let line = writer.seal(content, true);
        let (digest, back) = split(&line).unwrap();
        assert_eq!(back, content);
        let mut reader = Chain::start();
        reader.check(digest, &back, true).unwrap();
        assert_eq!(reader, writer);

        let flipped = content.replace("\"t\":3", "\"t\":2");
        assert!(Chain::start().check(digest, &flipped, true).is_err());
    }

    #[test]
    fn a_marker_does_not_move_the_chain() {
        let mut c = Chain::start();
        let before = c.clone();
        c.seal(r#"{"record":"resumed"}"#, false);
        assert_eq!(c, before);
    }

    #[test]
    fn malformed_chain_fields_are_not_split() {
        for bad in [
            "",
            "{}",
            r#"{"record":"header"}"#,
            r#"{"chain":"abc","record":"x"}"#,
            &format!(r#"{{"chain":"{}","record":"x"}}"#, "G".repeat(64)),
            &format!(r#"{{"chain":"{}"}}"#, "a".repeat(64)),
        ] {
            assert!(split(bad).is_none(), "{bad}");
        }
    }
}
