//! [`Tls`] in a build without the feature `tls`: the same calls, each
//! constructor an error that says how to get HTTPS, and no value.

use std::convert::Infallible;
use std::path::Path;

use hil_core::{HilError, Result};

use super::{CertSource, SELF_SIGNED_CERT};

/// A server certificate: in this build (no feature `tls`) none can be
/// made, so every method is unreachable and costs nothing.
#[derive(Clone, Debug)]
pub struct Tls {
    never: Infallible,
}

/// Why HTTPS is not served here, naming the file it was asked for with.
fn unavailable(path: &Path) -> HilError {
    HilError::unsupported(
        path.display().to_string(),
        "HTTPS",
        "this build leaves TLS out (hil-http's cargo feature `tls`): for the `hil` binary, \
         build it with `--features https` (`scripts/hil study ...` does)",
    )
}

impl Tls {
    /// In this build: [`HilError::Unsupported`] naming `cert`.
    pub fn from_pem_files(cert: &Path, _key: &Path) -> Result<Self> {
        Err(unavailable(cert))
    }

    /// In this build: [`HilError::Unsupported`] naming the certificate
    /// file it would have made in `dir`.
    pub fn self_signed_in(dir: &Path, _names: &[String]) -> Result<Self> {
        Err(unavailable(&dir.join(SELF_SIGNED_CERT)))
    }

    /// Where the certificate came from.
    pub fn source(&self) -> CertSource {
        match self.never {}
    }

    /// The certificate's SHA-256 fingerprint as browsers show it.
    pub fn fingerprint(&self) -> String {
        match self.never {}
    }

    /// The SHA-256 hash of the certificate's public key.
    pub fn public_key_sha256(&self) -> [u8; 32] {
        match self.never {}
    }

    pub(crate) fn config(&self) -> super::ServerConfig {
        match self.never {}
    }
}
