//! [`Tls`] with rustls (feature `tls`).

use std::path::Path;
use std::sync::Arc;

use hil_core::{HilError, Result};
use rustls::pki_types::pem::PemObject;
use rustls::pki_types::{CertificateDer, PrivateKeyDer};
use sha2::{Digest, Sha256};

use super::{CertSource, SELF_SIGNED_CERT, SELF_SIGNED_KEY, fingerprint};
use crate::secrets::{create_private, read_private};

/// A server certificate, its key and the TLS settings built from them.
#[derive(Clone)]
pub struct Tls {
    config: Arc<rustls::ServerConfig>,
    cert: CertificateDer<'static>,
    /// The certificate's public key (SubjectPublicKeyInfo, DER).
    public_key: Vec<u8>,
    source: CertSource,
}

impl std::fmt::Debug for Tls {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Never the key.
        f.debug_struct("Tls")
            .field("fingerprint", &self.fingerprint())
            .field("source", &self.source)
            .finish()
    }
}

fn tls_error(path: &Path, why: impl std::fmt::Display) -> HilError {
    HilError::invalid_input(path.display().to_string(), why.to_string())
}

/// Reads a PEM file: its text, or an error naming it.
fn read_pem(path: &Path, private: bool) -> Result<String> {
    if private {
        read_private(path)
    } else {
        hil_core::files::read_text(path, hil_core::files::limits::CONFIG)
    }
}

impl Tls {
    /// The lab's certificate chain (PEM, the server's certificate first)
    /// and its private key (PEM: PKCS#8, PKCS#1 or SEC1).
    pub fn from_pem_files(cert: &Path, key: &Path) -> Result<Self> {
        Self::from_pem(
            cert,
            &read_pem(cert, false)?,
            key,
            &read_pem(key, false)?,
            CertSource::Given,
        )
    }

    fn from_pem(
        cert_path: &Path,
        cert_pem: &str,
        key_path: &Path,
        key_pem: &str,
        source: CertSource,
    ) -> Result<Self> {
        let chain = CertificateDer::pem_slice_iter(cert_pem.as_bytes())
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| tls_error(cert_path, format!("not a PEM certificate chain: {e}")))?;
        let Some(cert) = chain.first().cloned() else {
            return Err(tls_error(
                cert_path,
                "holds no certificate (-----BEGIN CERTIFICATE-----)",
            ));
        };
        let key = PrivateKeyDer::from_pem_slice(key_pem.as_bytes())
            .map_err(|e| tls_error(key_path, format!("not a PEM private key: {e}")))?;
        let provider = Arc::new(rustls::crypto::ring::default_provider());
        let unusable = |e: rustls::Error| {
            tls_error(
                key_path,
                format!("cannot serve {} with this key: {e}", cert_path.display()),
            )
        };
        let public_key = provider
            .key_provider
            .load_private_key(key.clone_key())
            .map_err(unusable)?
            .public_key()
            .map(|k| k.as_ref().to_vec())
            .unwrap_or_default();
        let config = rustls::ServerConfig::builder_with_provider(provider)
            .with_safe_default_protocol_versions()
            .and_then(|b| b.with_no_client_auth().with_single_cert(chain, key))
            .map_err(unusable)?;
        Ok(Self {
            config: Arc::new(config),
            cert,
            public_key,
            source,
        })
    }

    /// The self-signed certificate kept in `dir`, made there on first use
    /// for `names` (host names and IP addresses the pages are opened at;
    /// `localhost` and the loopback addresses are always added). Later
    /// starts read it back, whatever the names then: the browser trusts
    /// it because the person checked its fingerprint, not its names.
    pub fn self_signed_in(dir: &Path, names: &[String]) -> Result<Self> {
        let (cert_path, key_path) = (dir.join(SELF_SIGNED_CERT), dir.join(SELF_SIGNED_KEY));
        match (cert_path.exists(), key_path.exists()) {
            (true, true) => {
                let cert = read_pem(&cert_path, false)?;
                let key = read_pem(&key_path, true)?;
                return Self::from_pem(
                    &cert_path,
                    &cert,
                    &key_path,
                    &key,
                    CertSource::SelfSignedKept,
                );
            }
            (false, false) => {}
            (has_cert, _) => {
                let (found, missing) = if has_cert {
                    (&cert_path, &key_path)
                } else {
                    (&key_path, &cert_path)
                };
                return Err(tls_error(
                    found,
                    format!(
                        "is here without {}; delete it to make a new self-signed certificate",
                        missing.display()
                    ),
                ));
            }
        }
        let mut all: Vec<String> = ["localhost", "127.0.0.1", "::1"]
            .into_iter()
            .map(String::from)
            .collect();
        for n in names {
            if !all.contains(n) {
                all.push(n.clone());
            }
        }
        let made = crate::self_signed::make(&all)
            .map_err(|e| tls_error(&cert_path, format!("cannot make a certificate: {e}")))?;
        let made = (made.cert_pem, made.key_pem);
        // The key first: a cut-short start leaves a key alone, which the
        // next start reports, never a certificate without its key.
        create_private(&key_path, made.1.as_bytes())?;
        std::fs::write(&cert_path, &made.0).map_err(|e| HilError::io("writing", &cert_path, e))?;
        Self::from_pem(
            &cert_path,
            &made.0,
            &key_path,
            &made.1,
            CertSource::SelfSignedNew,
        )
    }

    /// Where the certificate came from.
    pub fn source(&self) -> CertSource {
        self.source
    }

    /// The certificate's SHA-256 fingerprint as browsers show it
    /// (`AB:12:…`, 32 bytes): for the person to compare before trusting a
    /// self-signed certificate.
    pub fn fingerprint(&self) -> String {
        fingerprint(self.cert.as_ref())
    }

    /// The SHA-256 hash of the certificate's public key (its
    /// SubjectPublicKeyInfo), which Chromium's
    /// `--ignore-certificate-errors-spki-list` pins.
    pub fn public_key_sha256(&self) -> [u8; 32] {
        Sha256::digest(&self.public_key).into()
    }

    /// The server certificate (DER).
    pub fn certificate(&self) -> &CertificateDer<'static> {
        &self.cert
    }

    pub(crate) fn config(&self) -> super::ServerConfig {
        self.config.clone()
    }
}
