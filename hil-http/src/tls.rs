//! HTTPS for pages served beyond loopback ([`Server::start_tls`]): the
//! lab's own certificate, or a self-signed one made at the first start and
//! kept in the server's data folder, so its fingerprint, which the person
//! checks once in the browser, stays the same.
//!
//! With the cargo feature `tls`: rustls with the `ring` provider, and
//! self-signed certificates written by hand (`self_signed.rs`). Without
//! it, [`Tls`]'s constructors return [`HilError::Unsupported`] that says
//! how to get it, and no `Tls` can exist: the crates that serve only on
//! loopback (the web query channel, hil-py) build without rustls and ring.
//!
//! [`HilError::Unsupported`]: hil_core::HilError::Unsupported
//!
//! [`Server::start_tls`]: crate::Server::start_tls

use sha2::{Digest, Sha256};

#[cfg(feature = "tls")]
mod served;
#[cfg(not(feature = "tls"))]
mod unavailable;

#[cfg(feature = "tls")]
pub use served::Tls;
#[cfg(not(feature = "tls"))]
pub use unavailable::Tls;

/// Whether this build serves HTTPS: hil-http's cargo feature `tls`.
pub const AVAILABLE: bool = cfg!(feature = "tls");

/// What the server hands each new connection: rustls's settings, or,
/// without the feature, nothing that can exist.
#[cfg(feature = "tls")]
pub(crate) type ServerConfig = std::sync::Arc<rustls::ServerConfig>;
#[cfg(not(feature = "tls"))]
#[derive(Clone)]
pub(crate) enum ServerConfig {}

/// The self-signed certificate's file in a data folder.
pub const SELF_SIGNED_CERT: &str = "tls-cert.pem";
/// Its private key's file (readable by its owner only).
pub const SELF_SIGNED_KEY: &str = "tls-key.pem";

/// The SHA-256 fingerprint of a DER certificate as browsers show it:
/// 32 upper-case hex pairs joined by colons.
pub fn fingerprint(der: &[u8]) -> String {
    Sha256::digest(der)
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(":")
}

/// Where a [`Tls`]'s certificate came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CertSource {
    /// The lab's own files.
    Given,
    /// Self-signed, made now and stored.
    SelfSignedNew,
    /// Self-signed, made at an earlier start and read back.
    SelfSignedKept,
}
