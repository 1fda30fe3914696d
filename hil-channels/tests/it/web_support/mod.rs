//! Helpers shared by the web channel's HTTP test suites: a loopback
//! channel, a raw HTTP client, a query, and a person polling for it.

// Each suite uses its own subset of these.
#![allow(dead_code)]

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::thread::JoinHandle;
use std::time::Duration;

use hil_channels::{WebChannel, WebChannelConfig};
use hil_core::{ArmId, Context, Item, Query, QueryChannel, QueryKind, Response, ResponseType};

/// A channel on loopback answering within `timeout_s`: the channel, its
/// address and its token.
pub fn channel(timeout_s: f64) -> (WebChannel, SocketAddr, String) {
    let ch = WebChannel::start(WebChannelConfig {
        timeout_s,
        ..Default::default()
    })
    .unwrap();
    let addr = ch.addr();
    assert!(addr.ip().is_loopback(), "binds to loopback by default");
    let token = token_of(ch.url());
    assert_eq!(token.len(), 32);
    (ch, addr, token)
}

/// Sends raw bytes, returns (status, body).
pub fn raw(addr: SocketAddr, bytes: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    let _ = s.write_all(bytes);
    let _ = s.shutdown(std::net::Shutdown::Write);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out).to_string();
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

/// The headers the page itself sends with an answer.
pub fn same_origin(addr: SocketAddr) -> String {
    format!("Origin: http://{addr}\r\nContent-Type: application/json\r\n")
}

/// A question about a cantaloupe cube with the feeding actions.
pub fn query(t: u64, response: ResponseType) -> Query {
    Query::new(
        t,
        Item::new(0, "cantaloupe").with_description("a cube of cantaloupe"),
        QueryKind {
            response,
            ..Default::default()
        },
        hil_envs::feeding::action_space(),
        Context::new(vec![0.1]).unwrap(),
    )
    .with_oracle_best(ArmId(1))
}

/// Asks `q` on a thread; the handle returns the channel and the response.
pub fn ask_async(mut ch: WebChannel, q: Query) -> JoinHandle<(WebChannel, Response)> {
    std::thread::spawn(move || {
        let r = ch.ask(&q).unwrap();
        (ch, r)
    })
}

/// Waits until the page has an open question and returns its id.
pub fn open_id(addr: SocketAddr, token: &str) -> u64 {
    for _ in 0..500 {
        let (s, body) = get(addr, &format!("/{token}/api/query"));
        assert_eq!(s, 200);
        let v: serde_json::Value = serde_json::from_str(&body).unwrap();
        if v["state"] == "query" {
            return v["id"].as_u64().unwrap();
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("no question opened");
}

/// The token in a page URL `http://HOST:PORT/TOKEN/`.
pub fn token_of(url: &str) -> String {
    url.trim_end_matches('/')
        .rsplit('/')
        .next()
        .unwrap()
        .to_string()
}
