//! Secrets a server keeps in its data folder between runs (the study's
//! researcher token, a self-signed certificate's private key): files that
//! only their owner may read, so that a link or key stays the same across
//! restarts without being readable by other users of the machine.

use std::io::Write;
use std::path::Path;

use hil_core::{HilError, Result};

use crate::guard::random_token;

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

/// Reads a secret file, refusing one that other users may read or write
/// (the error says how to fix it).
pub fn read_private(path: &Path) -> Result<String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let meta = std::fs::metadata(path).map_err(|e| HilError::io("reading", path, e))?;
        let mode = meta.permissions().mode() & 0o777;
        if mode & 0o077 != 0 {
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
    hil_core::files::read_text(path, hil_core::files::limits::CONFIG)
}

/// The token kept in `path`, made (with [`random_token`]) and stored
/// there on first use: the same link after every restart.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("hil-http-doc-token-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("researcher.token");
/// let _ = std::fs::remove_file(&path);
/// let first = hil_http::secrets::stored_token(&path).unwrap();
/// assert_eq!(hil_http::secrets::stored_token(&path).unwrap(), first);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn stored_token(path: &Path) -> Result<String> {
    if !path.exists() {
        let token = random_token();
        create_private(path, format!("{token}\n").as_bytes())?;
        return Ok(token);
    }
    let text = read_private(path)?;
    let token = text.trim();
    if token.len() != 32 || !token.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(HilError::Data {
            path: path.to_path_buf(),
            record: 1,
            field: "token".into(),
            why: "must be 32 hex digits (delete the file for a new link)".into(),
        });
    }
    Ok(token.to_ascii_lowercase())
}
