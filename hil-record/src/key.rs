//! The secret key of a keyed log ([`super::chain`] then uses HMAC-SHA256).
//!
//! The key lives in its own file, kept outside the log (for instance beside
//! the study's data folder, never inside what is shared with the log): whoever
//! can read it can forge a log that verifies. So, as ssh does with private
//! keys, a key file that its group or others may read or write is refused,
//! and so is a key shorter than [`MIN_BYTES`].
//!
//! The file holds the key as hex on one line. [`RecordKey::generate`] writes
//! a new one (random bytes from the operating system, mode 0600, never over
//! an existing file). A log records only the key's [`RecordKey::id`], a
//! fingerprint from which the key cannot be recovered, so a verifier knows
//! which key the log needs.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use hil_core::error::{HilError, Result};

/// The fewest key bytes accepted (HMAC-SHA256's block of security).
pub const MIN_BYTES: usize = 32;
/// Bytes of a key that [`RecordKey::generate`] writes.
const NEW_BYTES: usize = 32;
/// A key file is a line of hex: more than this is not a key file.
const FILE_LIMIT: u64 = 4096;
/// Hex digits of a key id.
const ID_HEX: usize = 16;

/// A log's secret key, read from its file.
#[derive(Clone)]
pub struct RecordKey {
    bytes: Vec<u8>,
    path: PathBuf,
}

impl std::fmt::Debug for RecordKey {
    // Never the key itself: a debug print may end up in a log.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordKey")
            .field("path", &self.path)
            .field("id", &self.id())
            .finish()
    }
}

impl RecordKey {
    /// Reads the key at `path`: refused (naming the file) if its group or
    /// others may read or write it (an [`HilError::Io`] of kind
    /// `PermissionDenied`), and if it is not one line of hex or holds fewer
    /// than [`MIN_BYTES`] bytes (an [`HilError::Data`], field `key`).
    pub fn read(path: &Path) -> Result<Self> {
        let err = |field: &str, why: String| HilError::Data {
            path: path.to_path_buf(),
            record: 1,
            field: field.into(),
            why,
        };
        let text = hil_core::secrets::read_private(path, FILE_LIMIT)?;
        let bytes =
            super::chain::from_hex(text.trim_end_matches(['\n', '\r'])).ok_or_else(|| {
                err(
                    "key",
                    "a key file holds one line of hex digits (as `hil record keygen` writes)"
                        .into(),
                )
            })?;
        if bytes.len() < MIN_BYTES {
            return Err(err(
                "key",
                format!(
                    "the key has {} bytes; a record key needs at least {MIN_BYTES} \
                     (make one with `hil record keygen`)",
                    bytes.len()
                ),
            ));
        }
        Ok(Self {
            bytes,
            path: path.to_path_buf(),
        })
    }

    /// Writes a new random key to `path` (which must not exist) with mode
    /// 0600, and returns it.
    pub fn generate(path: &Path) -> Result<Self> {
        use rand::TryRngCore;
        let mut bytes = vec![0u8; NEW_BYTES];
        rand::rngs::OsRng.try_fill_bytes(&mut bytes).map_err(|e| {
            HilError::io("drawing random bytes for", path, std::io::Error::other(e))
        })?;
        hil_core::secrets::create_private(
            path,
            format!("{}\n", super::chain::hex(&bytes)).as_bytes(),
        )?;
        Ok(Self {
            bytes,
            path: path.to_path_buf(),
        })
    }

    /// The key's fingerprint, as a log's header records it: the first
    /// 16 hex digits of a SHA-256 over a fixed label and the key.
    pub fn id(&self) -> String {
        let mut h = Sha256::new();
        h.update(b"hil-record-key-id\0");
        h.update(&self.bytes);
        let mut id = super::chain::hex(&h.finalize());
        id.truncate(ID_HEX);
        id
    }

    /// The file the key was read from (for messages).
    pub fn path(&self) -> &Path {
        &self.path
    }

    pub(crate) fn bytes(&self) -> &[u8] {
        &self.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("hil-key-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_generated_key_reads_back_with_the_same_id() {
        let d = dir("gen");
        let path = d.join("k");
        let made = RecordKey::generate(&path).unwrap();
        let read = RecordKey::read(&path).unwrap();
        assert_eq!(made.id(), read.id());
        assert_eq!(read.bytes().len(), NEW_BYTES);
        // Never over an existing file.
        assert!(matches!(
            RecordKey::generate(&path),
            Err(HilError::Io { .. })
        ));
        // The debug print names the file and the id, never the key.
        let shown = format!("{read:?}");
        assert!(!shown.contains(&super::super::chain::hex(read.bytes())));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_key_others_may_read_is_refused() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("perm");
        let path = d.join("k");
        RecordKey::generate(&path).unwrap();
        assert_eq!(
            std::fs::metadata(&path).unwrap().permissions().mode() & 0o777,
            0o600
        );
        for mode in [0o640, 0o604, 0o620] {
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode)).unwrap();
            match RecordKey::read(&path) {
                Err(HilError::Io {
                    source, path: p, ..
                }) => {
                    assert_eq!(source.kind(), std::io::ErrorKind::PermissionDenied);
                    assert_eq!(p, path);
                }
                other => panic!("mode {mode:o}: {other:?}"),
            }
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn short_or_malformed_keys_are_refused() {
        let d = dir("short");
        for (i, text) in ["00ff\n", &"ab".repeat(31), "xyz", "", "abc"]
            .iter()
            .enumerate()
        {
            let path = d.join(format!("k{i}"));
            hil_core::secrets::create_private(&path, text.as_bytes()).unwrap();
            match RecordKey::read(&path) {
                Err(HilError::Data { field, .. }) => assert_eq!(field, "key", "{text:?}"),
                other => panic!("{text:?}: {other:?}"),
            }
        }
        std::fs::remove_dir_all(&d).unwrap();
    }
}
