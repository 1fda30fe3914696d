//! Secret files: readable and writable by their owner only. What a server
//! keeps in its data folder between runs (hil-http: a study's researcher
//! token, a self-signed certificate's private key) and the key of a keyed
//! interaction log (`hil_record::RecordKey`).
//!
//! As ssh does with private keys, a secret that other users may read or
//! write is refused rather than used: whoever can read it can act with it.

use std::io::Write;
use std::path::Path;

use crate::{HilError, Result};

/// Writes a new secret file readable and writable by its owner only
/// (mode 0600, set when the file is created, so it is never readable by
/// others, not even for a moment). Fails if the file exists.
pub fn create_private(path: &Path, contents: &[u8]) -> Result<()> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
    let mut file = options
        .open(path)
        .map_err(|e| HilError::io("creating", path, e))?;
    file.write_all(contents)
        .and_then(|()| file.sync_all())
        .map_err(|e| HilError::io("writing", path, e))
}

/// Reads a secret text file of at most `limit` bytes, refusing one that
/// other users may read or write with an [`HilError::Io`] of kind
/// `PermissionDenied` (the error says how to fix it).
pub fn read_private(path: &Path, limit: u64) -> Result<String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let meta = std::fs::metadata(path).map_err(|e| HilError::io("reading", path, e))?;
        let mode = meta.permissions().mode() & 0o777;
        // Not a file (a directory, a FIFO): read_text says so below, which
        // a complaint about its mode would hide.
        if meta.is_file() && mode & 0o077 != 0 {
            return Err(HilError::io(
                "reading",
                path,
                std::io::Error::new(
                    std::io::ErrorKind::PermissionDenied,
                    format!(
                        "this secret is open to other users (mode {mode:o}); make it the \
                         owner's only with `chmod 600 {}`",
                        path.display()
                    ),
                ),
            ));
        }
    }
    crate::files::read_text(path, limit)
}
