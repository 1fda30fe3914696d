//! The checks every request to a page passes before it is served, shared
//! by the web query page and the study pages:
//!
//! - the path starts with a secret token (`/TOKEN/...`), random per
//!   session (or per participant), compared in constant time;
//! - the `Host` header names this server ([`Site`]): an IP address,
//!   `localhost` or a name the operator allowed, on the bound port, which
//!   defeats DNS rebinding;
//! - a POST comes from the page itself ([`refuse_foreign_post`]).

use std::net::IpAddr;
use std::sync::OnceLock;

use hil_core::{HilError, Result};
use rand::Rng;

use crate::{Request, Response};

/// A fresh secret for a URL: 128 random bits as 32 hex digits.
///
/// ```
/// let t = hil_http::guard::random_token();
/// assert_eq!(t.len(), 32);
/// assert!(t.bytes().all(|b| b.is_ascii_hexdigit()));
/// ```
pub fn random_token() -> String {
    rand::rng()
        .random::<[u8; 16]>()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Compares without revealing, by timing, how much of the token matched.
pub fn same_token(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

/// Splits `/TOKEN/rest` into the token and the rest.
///
/// ```
/// use hil_http::guard::split_token;
/// assert_eq!(split_token("/abc/api/query"), ("abc", "api/query"));
/// assert_eq!(split_token("/abc"), ("abc", ""));
/// assert_eq!(split_token("/"), ("", ""));
/// ```
pub fn split_token(path: &str) -> (&str, &str) {
    let mut segments = path.trim_start_matches('/').splitn(2, '/');
    (segments.next().unwrap_or(""), segments.next().unwrap_or(""))
}

/// A 403 response saying why.
pub fn forbidden(why: &str) -> Response {
    Response::text(403, format!("forbidden: {why}"))
}

/// Every extra name a page may be reached by (a config's `allowed_hosts`)
/// must be a plain host name.
///
/// ```
/// use hil_http::guard::check_allowed_hosts;
/// assert!(check_allowed_hosts(&["robot.local".into()]).is_ok());
/// assert!(check_allowed_hosts(&["evil.com/x".into()]).is_err());
/// ```
pub fn check_allowed_hosts(hosts: &[String]) -> Result<()> {
    for h in hosts {
        if h.is_empty()
            || !h
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'.' || b == b'-')
        {
            return Err(HilError::invalid_parameter(
                "allowed_hosts",
                h,
                "must be a host name (letters, digits, dots, dashes)",
            ));
        }
    }
    Ok(())
}

/// Whether a `Host` header names a server on `port`: an IP address,
/// `localhost` or one of `allowed_hosts` (lower-case names). Refusing other
/// names defeats DNS rebinding.
///
/// ```
/// use hil_http::guard::host_allowed;
/// let allowed = ["robot.local".to_string()];
/// assert!(host_allowed(&allowed, 8765, "127.0.0.1:8765"));
/// assert!(host_allowed(&allowed, 8765, "[::1]:8765"));
/// assert!(host_allowed(&allowed, 8765, "Robot.Local:8765"));
/// assert!(!host_allowed(&allowed, 8765, "evil.example:8765"));
/// assert!(!host_allowed(&allowed, 8765, "127.0.0.1:9999"));
/// ```
pub fn host_allowed(allowed_hosts: &[String], port: u16, host: &str) -> bool {
    let host = host.to_ascii_lowercase();
    let (name, host_port) = match host.rsplit_once(':') {
        Some((n, p)) if !n.ends_with(']') || host.starts_with('[') => match p.parse::<u16>() {
            Ok(p) => (n.to_string(), p),
            Err(_) => return false,
        },
        _ => (host.clone(), 80),
    };
    if host_port != port {
        return false;
    }
    let bare = name.trim_start_matches('[').trim_end_matches(']');
    bare.parse::<IpAddr>().is_ok()
        || bare == "localhost"
        || allowed_hosts.iter().any(|h| *h == bare)
}

/// The names and the port a server answers to, for the `Host` check.
///
/// The port is known only once the server is bound, after the service
/// that checks it was made: [`set_port`](Self::set_port) fills it in, and
/// until then every request is answered 503.
#[derive(Debug)]
pub struct Site {
    allowed_hosts: Vec<String>,
    port: OnceLock<u16>,
}

impl Site {
    /// A site reached by IP address, `localhost` and `allowed_hosts` (any
    /// case), port still unknown.
    pub fn new(allowed_hosts: &[String]) -> Self {
        Self {
            allowed_hosts: allowed_hosts
                .iter()
                .map(|h| h.to_ascii_lowercase())
                .collect(),
            port: OnceLock::new(),
        }
    }

    /// Records the port the server is bound to (the first call counts).
    pub fn set_port(&self, port: u16) {
        let _ = self.port.set(port);
    }

    /// Refuses a request whose `Host` does not name this site (403), or
    /// that arrived before the port was known (503).
    pub fn check_host(&self, req: &Request) -> std::result::Result<(), Response> {
        let Some(&port) = self.port.get() else {
            return Err(Response::text(503, "starting"));
        };
        match req.header("host") {
            Some(h) if host_allowed(&self.allowed_hosts, port, h) => Ok(()),
            _ => Err(forbidden("unexpected Host")),
        }
    }
}

/// Refuses a POST that does not come from the page itself: browsers always
/// send Origin on a POST, and a JSON body cannot be sent cross-origin
/// without a CORS preflight, which this server never grants.
pub fn refuse_foreign_post(req: &Request) -> Option<Response> {
    let host = req.header("host").unwrap_or("");
    match req.header("origin") {
        Some(o) if o.eq_ignore_ascii_case(&format!("{}://{host}", req.scheme.as_str())) => {}
        Some(_) => {
            return Some(forbidden(
                "answers are accepted only from the page's own origin",
            ));
        }
        None => return Some(forbidden("answers need an Origin header")),
    }
    if let Some(site) = req.header("sec-fetch-site")
        && site != "same-origin"
    {
        return Some(forbidden(
            "answers are accepted only from the page's own origin",
        ));
    }
    let is_json = req.header("content-type").is_some_and(|c| {
        c.split(';')
            .next()
            .unwrap_or("")
            .trim()
            .eq_ignore_ascii_case("application/json")
    });
    if !is_json {
        return Some(Response::text(
            415,
            "the answer must be sent as application/json",
        ));
    }
    None
}
