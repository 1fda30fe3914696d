//! A raw HTTP/1.1 client for tests: writes exactly the bytes given, reads
//! the whole response, and helpers to wait on a server's state.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

#[cfg(feature = "tls")]
mod https;
#[cfg(feature = "tls")]
pub use https::{get_https, post_https, raw_https};

/// Sends raw bytes, returns (status, body).
///
/// # Panics
///
/// If the server cannot be reached or answers without a status line.
pub fn raw(addr: SocketAddr, bytes: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    let _ = s.write_all(bytes);
    let _ = s.shutdown(std::net::Shutdown::Write);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    status_and_body(&out)
}

/// A response's status and body.
fn status_and_body(out: &[u8]) -> (u16, String) {
    let text = String::from_utf8_lossy(out).to_string();
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"));
    let body = text
        .split_once("\r\n\r\n")
        .map(|(_, b)| b.to_string())
        .unwrap_or_default();
    (status, body)
}

/// GET `path` with a matching Host header.
pub fn get(addr: SocketAddr, path: &str) -> (u16, String) {
    raw(
        addr,
        format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes(),
    )
}

/// POST `body` to `path` with a matching Host header and `extra_headers`.
pub fn post(addr: SocketAddr, path: &str, extra_headers: &str, body: &str) -> (u16, String) {
    raw(
        addr,
        format!(
            "POST {path} HTTP/1.1\r\nHost: {addr}\r\n{extra_headers}Content-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .as_bytes(),
    )
}

/// The headers a page served at `addr` sends with its own POSTs.
pub fn same_origin(addr: SocketAddr) -> String {
    format!("Origin: http://{addr}\r\nContent-Type: application/json\r\n")
}

/// The token in a page URL `http://HOST:PORT/TOKEN/`.
pub fn token_of(url: &str) -> String {
    url.trim_end_matches('/')
        .rsplit('/')
        .next()
        .unwrap_or_default()
        .to_string()
}

/// Waits (polling) until `cond` holds; panics after a minute, so that a
/// broken server fails the test instead of hanging it.
pub fn wait_for(what: &str, mut cond: impl FnMut() -> bool) {
    let give_up = Instant::now() + Duration::from_secs(60);
    while !cond() {
        assert!(Instant::now() < give_up, "gave up waiting for {what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Whether the server has closed `s` or answered on it (without blocking).
pub fn closed_or_answered(s: &mut TcpStream) -> bool {
    s.set_nonblocking(true).unwrap();
    let mut byte = [0u8; 1];
    let done = match s.read(&mut byte) {
        Ok(_) => true, // a response, or the end of the stream
        Err(e) => e.kind() != ErrorKind::WouldBlock,
    };
    s.set_nonblocking(false).unwrap();
    done
}
