//! HTTPS and the secrets kept for it: a self-signed certificate made once
//! and read back, the lab's files checked; a token kept owner-only; the
//! server over TLS: a client that pins the certificate's fingerprint is
//! served and told the scheme, a client that trickles its handshake is cut
//! off at the request deadline, like one that trickles its request, and a
//! plain-HTTP request to the TLS port gets no answer. Loopback only.

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::time::{Duration, Instant};

use hil_core::HilError;
use hil_http::secrets::stored_token;
use hil_http::testing::client::{get_https, post_https, raw};
use hil_http::tls::{CertSource, SELF_SIGNED_CERT, SELF_SIGNED_KEY, Tls};
use hil_http::{Limits, Request, Response, Server, Service, guard};

/// Answers with the request's scheme; refuses foreign POSTs.
struct Scheme;

impl Service for Scheme {
    fn trusted(&self, _path: &str) -> bool {
        false
    }

    fn handle(&self, req: &Request) -> Response {
        if req.method == "POST"
            && let Some(refused) = guard::refuse_foreign_post(req)
        {
            return refused;
        }
        Response::text(200, req.scheme.as_str())
    }
}

fn temp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("hil-http-it-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn https_is_served_to_a_pinned_client_and_trickling_handshakes_time_out() {
    let dir = temp("https");
    let tls = Tls::self_signed_in(&dir, &[]).unwrap();
    let limits = Limits {
        request_deadline: Duration::from_millis(700),
        ..Limits::default()
    };
    let server = Server::start_tls(
        "127.0.0.1:0".parse().unwrap(),
        Arc::new(Scheme),
        limits,
        &tls,
    )
    .unwrap();
    let addr = server.addr();
    let fp = tls.fingerprint();
    assert_eq!(get_https(addr, &fp, "/x"), (200, "https".to_string()));
    // The page's own origin is the https one.
    let json = "Content-Type: application/json\r\n";
    let post = |origin: &str| {
        post_https(
            addr,
            &fp,
            "/x",
            &format!("Origin: {origin}\r\n{json}"),
            "{}",
        )
        .0
    };
    assert_eq!(post(&format!("https://{addr}")), 200);
    assert_eq!(post(&format!("http://{addr}")), 403);
    // A client that sends a real ClientHello a byte at a time is cut off
    // at the deadline (not before: the bytes are valid), not served as
    // long as it keeps trickling.
    let hello = client_hello();
    let mut slow = TcpStream::connect(addr).unwrap();
    slow.set_read_timeout(Some(Duration::from_millis(1)))
        .unwrap();
    let began = Instant::now();
    let mut cut_off = None;
    for byte in &hello {
        let mut buf = [0u8; 64];
        let closed = slow.write_all(&[*byte]).is_err()
            || match slow.read(&mut buf) {
                Ok(_) => true,
                Err(e) => !matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut),
            };
        if closed {
            cut_off = Some(began.elapsed());
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let cut_off = cut_off.expect("the whole trickled handshake was taken");
    assert!(
        cut_off >= Duration::from_millis(650) && cut_off < Duration::from_secs(5),
        "cut off after {cut_off:?}, {} of {} bytes",
        hello.len(),
        hello.len()
    );
    // Plain HTTP to the TLS port: no page.
    let plain = std::panic::catch_unwind(|| raw(addr, b"GET /x HTTP/1.1\r\nHost: a\r\n\r\n"));
    assert!(!matches!(plain, Ok((200, _))), "{plain:?}");
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The bytes of a real TLS ClientHello (rustls's, as a browser would send
/// one), for a client that sends them slowly.
fn client_hello() -> Vec<u8> {
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let config = rustls::ClientConfig::builder_with_provider(provider)
        .with_safe_default_protocol_versions()
        .unwrap()
        .with_root_certificates(rustls::RootCertStore::empty())
        .with_no_client_auth();
    let name = rustls::pki_types::ServerName::try_from("localhost").unwrap();
    let mut conn = rustls::ClientConnection::new(Arc::new(config), name).unwrap();
    let mut out = Vec::new();
    while conn.wants_write() {
        conn.write_tls(&mut out).unwrap();
    }
    assert!(out.len() > 40, "{} bytes", out.len());
    out
}

/// Made once, then read back: the same fingerprint; the key is the
/// owner's only; half a pair is refused.
#[test]
fn a_self_signed_certificate_is_kept() {
    let dir = temp("kept");
    let first = Tls::self_signed_in(&dir, &["study.local".into()]).unwrap();
    assert_eq!(first.source(), CertSource::SelfSignedNew);
    let fp = first.fingerprint();
    assert_eq!(fp.len(), 32 * 3 - 1, "{fp}");
    let again = Tls::self_signed_in(&dir, &[]).unwrap();
    assert_eq!(again.source(), CertSource::SelfSignedKept);
    assert_eq!(again.fingerprint(), fp);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(dir.join(SELF_SIGNED_KEY))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o600);
    }
    // The lab's files are read the same way.
    let given =
        Tls::from_pem_files(&dir.join(SELF_SIGNED_CERT), &dir.join(SELF_SIGNED_KEY)).unwrap();
    assert_eq!(
        (given.source(), given.fingerprint()),
        (CertSource::Given, fp)
    );
    std::fs::remove_file(dir.join(SELF_SIGNED_KEY)).unwrap();
    let e = Tls::self_signed_in(&dir, &[]).unwrap_err();
    assert!(matches!(e, HilError::InvalidInput { .. }), "{e:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file that is not a certificate, or a key that is not the
/// certificate's, is refused naming the file.
#[test]
fn bad_lab_files_are_named() {
    let (a, b) = (temp("bad-a"), temp("bad-b"));
    Tls::self_signed_in(&a, &[]).unwrap();
    Tls::self_signed_in(&b, &[]).unwrap();
    let e = Tls::from_pem_files(&a.join(SELF_SIGNED_KEY), &a.join(SELF_SIGNED_KEY)).unwrap_err();
    assert!(e.to_string().contains(SELF_SIGNED_KEY), "{e}");
    let e = Tls::from_pem_files(&a.join(SELF_SIGNED_CERT), &b.join(SELF_SIGNED_KEY)).unwrap_err();
    assert!(matches!(e, HilError::InvalidInput { .. }), "{e:?}");
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

#[cfg(unix)]
#[test]
fn a_stored_token_is_the_owners_only_and_stays() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp("token");
    let path = dir.join("t.token");
    let first = stored_token(&path).unwrap();
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    assert_eq!(stored_token(&path).unwrap(), first);
    // Opened up to others, it is refused, not used.
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
    let e = stored_token(&path).unwrap_err();
    assert!(matches!(e, HilError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("chmod 600"), "{e}");
    // A damaged token is refused, naming the file.
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
    std::fs::write(&path, "not a token\n").unwrap();
    let e = stored_token(&path).unwrap_err();
    assert!(e.to_string().contains("t.token"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The self-signed certificate is a well-formed X.509 server certificate
/// whose signature checks: a WebPKI verifier that trusts it as its own
/// root accepts it for every name it was made for, and no other.
#[test]
fn the_self_signed_certificate_verifies_as_its_own_root_for_its_names() {
    use rustls::client::WebPkiServerVerifier;
    use rustls::client::danger::ServerCertVerifier;
    use rustls::pki_types::{ServerName, UnixTime};

    let dir = temp("webpki");
    let tls =
        Tls::self_signed_in(&dir, &["lab-laptop.local".into(), "192.168.1.20".into()]).unwrap();
    let mut roots = rustls::RootCertStore::empty();
    roots.add(tls.certificate().clone()).unwrap();
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let verifier = WebPkiServerVerifier::builder_with_provider(Arc::new(roots), provider)
        .build()
        .unwrap();
    let verify = |name: &str| {
        verifier.verify_server_cert(
            tls.certificate(),
            &[],
            &ServerName::try_from(name.to_string()).unwrap(),
            &[],
            UnixTime::now(),
        )
    };
    for name in [
        "localhost",
        "127.0.0.1",
        "::1",
        "lab-laptop.local",
        "192.168.1.20",
    ] {
        verify(name).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    assert!(verify("example.org").is_err());
    assert!(verify("10.0.0.1").is_err());
    let _ = std::fs::remove_dir_all(dir);
}
