//! Secrets a server keeps in its data folder between runs (the study's
//! researcher token, a self-signed certificate's private key): files that
//! only their owner may read, so that a link or key stays the same across
//! restarts without being readable by other users of the machine.

use std::path::Path;

use hil_core::{HilError, Result};

use crate::guard::random_token;

pub use hil_core::secrets::create_private;

/// Reads a secret file (at most [`hil_core::files::limits::CONFIG`]
/// bytes), refusing one that other users may read or write
/// ([`hil_core::secrets::read_private`]).
pub fn read_private(path: &Path) -> Result<String> {
    hil_core::secrets::read_private(path, hil_core::files::limits::CONFIG)
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
