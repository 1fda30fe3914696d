//! # hil-http
//!
//! The small, strict HTTP/1.1 server that serves hil's browser pages — the
//! web query channel (`hil-channels`) and the workload study (`hil-study`)
//! — and what both need around it:
//!
//! - [`Server`], [`Service`], [`Request`], [`Response`], [`Limits`]: one
//!   request per connection, hard limits on every size and on time, a
//!   bounded number of connections; [`parse`] is the request parser alone.
//! - [`guard`]: the checks every page request passes — the per-session
//!   token in the path, the `Host` header (against DNS rebinding), and that
//!   a POST comes from the page's own origin with a JSON body.
//! - [`page`]: serving a page's files: the top every page shares (head,
//!   header, switch-scanning settings), the shared style sheet and
//!   single-switch scanning script, compiled-in assets, and item pictures
//!   from a folder.
//! - [`tls`]: HTTPS ([`Server::start_tls`]) with the lab's certificate or
//!   a self-signed one kept in the data folder, and its fingerprint
//!   (cargo feature `tls`; without it, asking for HTTPS is an error that
//!   says how to get it).
//! - [`urls`]: the URLs to print for the address the server is bound to.
//! - [`secrets`]: tokens and keys kept between runs in files only their
//!   owner may read.
//! - `testing` (feature `testing`): a raw HTTP client and a headless
//!   Chromium driver for the pages' test suites.
//!
//! No dependency on an async runtime or another HTTP crate (the
//! hil-http README says why).
//!
//! ## The server's limits
//!
//! Limits (answered with the status code in parentheses): request head
//! 16 KiB (431), request target 2 KiB (414), body 16 KiB (413), a body
//! without `Content-Length` (411), chunked bodies (501), a malformed request
//! (400), a whole request not received within 10 s of connecting (408)
//! (however steadily it trickles in; over HTTPS the handshake counts too).
//!
//! Connections ([`Limits`]): 64 for clients that have not shown the
//! session's token (when all are taken, a newcomer takes the oldest one's
//! slot and that connection is closed), and 16 more, which strangers cannot
//! take, for requests whose request line carries the token [503 when those
//! are all busy]. So clients that trickle bytes, or just connect and wait,
//! cannot lock out the person who holds the token.

use std::collections::HashMap;
use std::time::Duration;

pub mod guard;
pub mod page;
pub mod parse;
pub mod secrets;
#[cfg(feature = "tls")]
mod self_signed;
mod server;
mod slots;
#[cfg(feature = "testing")]
pub mod testing;
pub mod tls;
pub mod urls;

pub use server::Server;
pub use slots::Occupancy;

/// Longest request line plus headers.
pub const MAX_HEAD_BYTES: usize = 16 * 1024;
/// Longest request target (path and query).
pub const MAX_TARGET_BYTES: usize = 2 * 1024;
/// Longest request body.
pub const MAX_BODY_BYTES: usize = 16 * 1024;

/// The server's connection limits and request deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Connections held at once by clients that have not (yet) shown the
    /// token; when full, the oldest is closed to make room (default 64).
    pub open_slots: usize,
    /// Connections held at once by requests whose request line carries
    /// the token (default 16); more get 503.
    pub trusted_slots: usize,
    /// Time from accepting a connection to having its whole request
    /// (default 10 s); later, the client gets 408.
    pub request_deadline: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            open_slots: 64,
            trusted_slots: 16,
            request_deadline: Duration::from_secs(10),
        }
    }
}

/// What a [`Server`] serves.
pub trait Service: Send + Sync + 'static {
    /// Whether a request for `path` comes from a client that holds the
    /// session's secret, so that it may use the trusted connection slots.
    /// Called once per connection, as soon as the request line arrives.
    /// This only places the connection: [`handle`](Self::handle) still
    /// checks everything.
    fn trusted(&self, path: &str) -> bool;

    /// The response to a whole, well-formed request.
    fn handle(&self, req: &Request) -> Response;
}

/// How a request arrived.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheme {
    /// Plain HTTP (loopback).
    #[default]
    Http,
    /// HTTPS ([`Server::start_tls`]).
    Https,
}

impl Scheme {
    /// `http` or `https`, as in a URL.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Http => "http",
            Self::Https => "https",
        }
    }
}

/// A parsed request.
#[derive(Debug, Clone)]
pub struct Request {
    /// Whether it came over plain HTTP or HTTPS.
    pub scheme: Scheme,
    /// `GET`, `POST`, ...
    pub method: String,
    /// The path, without the query string.
    pub path: String,
    /// Headers, names lower-cased.
    pub headers: HashMap<String, String>,
    /// The body.
    pub body: Vec<u8>,
}

impl Request {
    /// A header by lower-case name.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers.get(name).map(String::as_str)
    }
}

/// A response to send.
#[derive(Debug, Clone)]
pub struct Response {
    /// Status code.
    pub status: u16,
    /// Content type of the body.
    pub content_type: &'static str,
    /// The body.
    pub body: Vec<u8>,
}

impl Response {
    /// A plain-text response.
    pub fn text(status: u16, body: impl Into<String>) -> Self {
        Self {
            status,
            content_type: "text/plain; charset=utf-8",
            body: body.into().into_bytes(),
        }
    }

    /// A JSON response.
    pub fn json(status: u16, value: &serde_json::Value) -> Self {
        Self {
            status,
            content_type: "application/json",
            body: value.to_string().into_bytes(),
        }
    }
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        411 => "Length Required",
        413 => "Content Too Large",
        414 => "URI Too Long",
        415 => "Unsupported Media Type",
        422 => "Unprocessable Content",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        501 => "Not Implemented",
        503 => "Service Unavailable",
        _ => "Status",
    }
}
