//! The HTTPS client (feature `tls`): pins the server's certificate by its
//! fingerprint.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

use super::status_and_body;

/// Sends raw bytes over HTTPS to a server whose certificate has the
/// SHA-256 `fingerprint` (as [`Tls::fingerprint`](crate::tls::Tls::fingerprint)
/// prints it; any other certificate is refused), returns (status, body).
///
/// # Panics
///
/// If the server cannot be reached, its certificate is not the pinned
/// one, or it answers without a status line.
pub fn raw_https(addr: SocketAddr, fingerprint: &str, bytes: &[u8]) -> (u16, String) {
    let provider = std::sync::Arc::new(rustls::crypto::ring::default_provider());
    let config = rustls::ClientConfig::builder_with_provider(provider.clone())
        .with_safe_default_protocol_versions()
        .unwrap()
        .dangerous()
        .with_custom_certificate_verifier(std::sync::Arc::new(Pinned {
            fingerprint: fingerprint.to_string(),
            provider,
        }))
        .with_no_client_auth();
    let name = rustls::pki_types::ServerName::IpAddress(addr.ip().into());
    let conn = rustls::ClientConnection::new(std::sync::Arc::new(config), name).unwrap();
    let tcp = TcpStream::connect(addr).unwrap();
    tcp.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    let mut tls = rustls::StreamOwned::new(conn, tcp);
    tls.write_all(bytes).unwrap();
    tls.flush().unwrap();
    let mut out = Vec::new();
    // The server ends with close_notify; an abrupt end still keeps what came.
    let _ = tls.read_to_end(&mut out);
    status_and_body(&out)
}

/// GET `path` over HTTPS (see [`raw_https`]) with a matching Host header.
pub fn get_https(addr: SocketAddr, fingerprint: &str, path: &str) -> (u16, String) {
    raw_https(
        addr,
        fingerprint,
        format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes(),
    )
}

/// POST `body` to `path` over HTTPS (see [`raw_https`]) with a matching
/// Host header and `extra_headers`.
pub fn post_https(
    addr: SocketAddr,
    fingerprint: &str,
    path: &str,
    extra_headers: &str,
    body: &str,
) -> (u16, String) {
    raw_https(
        addr,
        fingerprint,
        format!(
            "POST {path} HTTP/1.1\r\nHost: {addr}\r\n{extra_headers}Content-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .as_bytes(),
    )
}

/// Accepts exactly the certificate with the pinned fingerprint (and checks
/// the handshake's signatures with it).
#[derive(Debug)]
struct Pinned {
    fingerprint: String,
    provider: std::sync::Arc<rustls::crypto::CryptoProvider>,
}

impl rustls::client::danger::ServerCertVerifier for Pinned {
    fn verify_server_cert(
        &self,
        end_entity: &rustls::pki_types::CertificateDer<'_>,
        _intermediates: &[rustls::pki_types::CertificateDer<'_>],
        _server_name: &rustls::pki_types::ServerName<'_>,
        _ocsp_response: &[u8],
        _now: rustls::pki_types::UnixTime,
    ) -> Result<rustls::client::danger::ServerCertVerified, rustls::Error> {
        let seen = crate::tls::fingerprint(end_entity.as_ref());
        if seen.eq_ignore_ascii_case(&self.fingerprint) {
            Ok(rustls::client::danger::ServerCertVerified::assertion())
        } else {
            Err(rustls::Error::General(format!(
                "certificate {seen} is not the pinned {}",
                self.fingerprint
            )))
        }
    }

    fn verify_tls12_signature(
        &self,
        message: &[u8],
        cert: &rustls::pki_types::CertificateDer<'_>,
        dss: &rustls::DigitallySignedStruct,
    ) -> Result<rustls::client::danger::HandshakeSignatureValid, rustls::Error> {
        rustls::crypto::verify_tls12_signature(
            message,
            cert,
            dss,
            &self.provider.signature_verification_algorithms,
        )
    }

    fn verify_tls13_signature(
        &self,
        message: &[u8],
        cert: &rustls::pki_types::CertificateDer<'_>,
        dss: &rustls::DigitallySignedStruct,
    ) -> Result<rustls::client::danger::HandshakeSignatureValid, rustls::Error> {
        rustls::crypto::verify_tls13_signature(
            message,
            cert,
            dss,
            &self.provider.signature_verification_algorithms,
        )
    }

    fn supported_verify_schemes(&self) -> Vec<rustls::SignatureScheme> {
        self.provider
            .signature_verification_algorithms
            .supported_schemes()
    }
}
