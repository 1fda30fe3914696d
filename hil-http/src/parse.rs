//! The request parser: bytes in, a [`Request`] or a refusal out. No I/O,
//! so that it can be fuzzed on its own and fed by any reader, in pieces of
//! any size; the result never depends on how the bytes were split.

use std::collections::HashMap;

use super::{MAX_BODY_BYTES, MAX_HEAD_BYTES, MAX_TARGET_BYTES, Request, Response};

/// Why a request is refused, with the status code to answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Refusal {
    /// The HTTP status code (400, 408, 411, 413, 414, 431 or 501).
    pub status: u16,
    /// A short reason, sent as the response body.
    pub why: &'static str,
}

impl Refusal {
    const fn new(status: u16, why: &'static str) -> Self {
        Self { status, why }
    }
}

impl From<Refusal> for Response {
    fn from(r: Refusal) -> Self {
        Response::text(r.status, r.why)
    }
}

/// A malformed request (400).
fn bad(why: &'static str) -> Refusal {
    Refusal::new(400, why)
}

/// What the bytes received so far amount to.
#[derive(Debug)]
pub enum Progress {
    /// A prefix of a request: more bytes are needed.
    NeedMore,
    /// A whole request (bytes after its body are ignored: one request per
    /// connection).
    Complete(Request),
}

/// The parsed request line.
#[derive(Debug, Clone)]
struct Line {
    method: String,
    /// The target's path, without the query string.
    path: String,
    /// Where the line's CRLF starts.
    end: usize,
}

/// The parsed head: request line, headers, and where the body starts.
#[derive(Debug)]
struct Head {
    headers: HashMap<String, String>,
    body_start: usize,
    body_len: usize,
}

/// An incremental HTTP/1.1 request parser with hil's limits
/// ([`MAX_HEAD_BYTES`], [`MAX_TARGET_BYTES`], [`MAX_BODY_BYTES`]).
///
/// Feed it the bytes of one connection with [`push`](Self::push) until it
/// returns a request or a refusal; call [`end_of_input`](Self::end_of_input)
/// if the client closes first. The request line is available from
/// [`path`](Self::path) as soon as it is complete, before the headers,
/// so that a server can tell early who is asking.
#[derive(Debug, Default)]
pub struct RequestParser {
    buf: Vec<u8>,
    /// How much of `buf` has been searched for the end of the head, so
    /// that a head sent one byte at a time is still scanned once.
    scanned: usize,
    line: Option<Line>,
    head: Option<Head>,
    /// Set once a request or a refusal has been returned.
    finished: bool,
}

impl RequestParser {
    /// Adds the next bytes of the connection. Once this has returned a
    /// request or a refusal, the parser is spent and refuses more input.
    pub fn push(&mut self, bytes: &[u8]) -> Result<Progress, Refusal> {
        if self.finished {
            return Err(bad("more than one request on a connection"));
        }
        let result = self.advance(bytes);
        if !matches!(result, Ok(Progress::NeedMore)) {
            self.finished = true;
        }
        result
    }

    /// The request's path (without the query string), once the request
    /// line has arrived and is valid.
    pub fn path(&self) -> Option<&str> {
        self.line.as_ref().map(|l| l.path.as_str())
    }

    /// How many bytes the parser holds. While it needs more, never more
    /// than [`MAX_HEAD_BYTES`] + 4 + [`MAX_BODY_BYTES`]: a connection's
    /// memory is bounded whatever the client sends (what the fuzz tests
    /// check).
    pub fn buffered(&self) -> usize {
        self.buf.len()
    }

    /// What to answer when the client stops sending before a whole
    /// request: `None` if it sent nothing (it just went away).
    pub fn end_of_input(&self) -> Option<Refusal> {
        if self.buf.is_empty() {
            None
        } else if self.head.is_some() {
            Some(bad("body shorter than Content-Length"))
        } else {
            Some(bad("incomplete request"))
        }
    }

    fn advance(&mut self, bytes: &[u8]) -> Result<Progress, Refusal> {
        if let Some(head) = &self.head {
            // Keep no more than the body needs.
            let want = (head.body_start + head.body_len).saturating_sub(self.buf.len());
            self.buf.extend_from_slice(&bytes[..want.min(bytes.len())]);
            return Ok(self.complete());
        }
        self.buf.extend_from_slice(bytes);
        if self.line.is_none() {
            let from = self.scanned.saturating_sub(1);
            match find(&self.buf[from..], b"\r\n").map(|p| from + p) {
                Some(end) => self.line = Some(parse_line(&self.buf[..end], end)?),
                None if self.buf.len() > MAX_HEAD_BYTES => {
                    return Err(Refusal::new(431, "request head too large"));
                }
                None => {
                    self.scanned = self.buf.len();
                    return Ok(Progress::NeedMore);
                }
            }
        }
        let line_end = self.line.as_ref().map_or(0, |l| l.end);
        // The head ends at the first empty line; the request line's CRLF
        // may be the first half of it. Each search resumes where the last
        // one stopped, less the bytes of a terminator split between pushes.
        let from = self.scanned.saturating_sub(3).max(line_end);
        let Some(end) = find(&self.buf[from..], b"\r\n\r\n").map(|p| from + p) else {
            self.scanned = self.buf.len();
            if self.buf.len() > MAX_HEAD_BYTES {
                return Err(Refusal::new(431, "request head too large"));
            }
            return Ok(Progress::NeedMore);
        };
        if end > MAX_HEAD_BYTES {
            return Err(Refusal::new(431, "request head too large"));
        }
        let fields = if end > line_end {
            &self.buf[line_end + 2..end]
        } else {
            &[][..]
        };
        let method = self.line.as_ref().map_or("", |l| l.method.as_str());
        let (headers, body_len) = parse_fields(fields, method)?;
        self.head = Some(Head {
            headers,
            body_start: end + 4,
            body_len,
        });
        // Pipelined requests are not served: drop what follows the body.
        self.buf.truncate(end + 4 + body_len);
        Ok(self.complete())
    }

    /// The request, if the whole body has arrived.
    fn complete(&mut self) -> Progress {
        let (Some(line), Some(head)) = (&self.line, &mut self.head) else {
            return Progress::NeedMore;
        };
        if self.buf.len() < head.body_start + head.body_len {
            return Progress::NeedMore;
        }
        Progress::Complete(Request {
            // The server sets it (the parser sees only bytes).
            scheme: crate::Scheme::Http,
            method: line.method.clone(),
            path: line.path.clone(),
            headers: std::mem::take(&mut head.headers),
            body: self.buf[head.body_start..].to_vec(),
        })
    }
}

/// Parses `METHOD TARGET VERSION` (without its CRLF, which starts at `end`).
fn parse_line(line: &[u8], end: usize) -> Result<Line, Refusal> {
    let line = std::str::from_utf8(line).map_err(|_| bad("request head is not UTF-8"))?;
    let mut parts = line.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(bad("malformed request line"));
    };
    if method.is_empty() || !method.bytes().all(|b| b.is_ascii_uppercase()) {
        return Err(bad("malformed method"));
    }
    if version != "HTTP/1.1" && version != "HTTP/1.0" {
        return Err(bad("unsupported HTTP version"));
    }
    if target.len() > MAX_TARGET_BYTES {
        return Err(Refusal::new(414, "request target too long"));
    }
    if !target.starts_with('/') || target.bytes().any(|b| b <= b' ' || b == 0x7f) {
        return Err(bad("malformed request target"));
    }
    Ok(Line {
        method: method.to_string(),
        path: target.split('?').next().unwrap_or("").to_string(),
        end,
    })
}

/// Parses the header fields (CRLF-separated, without the final empty
/// line) and works out the body's length.
fn parse_fields(fields: &[u8], method: &str) -> Result<(HashMap<String, String>, usize), Refusal> {
    let fields = std::str::from_utf8(fields).map_err(|_| bad("request head is not UTF-8"))?;
    let mut headers = HashMap::new();
    // No empty line can occur inside: the head ends at the first one.
    for line in fields.split("\r\n").filter(|l| !l.is_empty()) {
        let Some((name, value)) = line.split_once(':') else {
            return Err(bad("malformed header"));
        };
        if name.is_empty() || name.bytes().any(|b| b <= b' ' || b == b':' || b >= 0x7f) {
            return Err(bad("malformed header name"));
        }
        let name = name.to_ascii_lowercase();
        // Two of these could be read differently by a proxy and by us.
        if headers.contains_key(&name)
            && matches!(name.as_str(), "content-length" | "host" | "origin")
        {
            return Err(bad("duplicate header"));
        }
        headers.insert(name, value.trim().to_string());
    }
    if headers.contains_key("transfer-encoding") {
        return Err(Refusal::new(501, "chunked bodies are not supported"));
    }
    let length = match headers.get("content-length") {
        // Digits only: `parse` alone would also take a sign.
        Some(v) if !v.is_empty() && v.bytes().all(|b| b.is_ascii_digit()) => v
            .parse::<usize>()
            .map_err(|_| Refusal::new(413, "request body too large"))?,
        Some(_) => return Err(bad("malformed Content-Length")),
        None if matches!(method, "POST" | "PUT" | "PATCH") => {
            return Err(Refusal::new(411, "Content-Length required"));
        }
        None => 0,
    };
    if length > MAX_BODY_BYTES {
        return Err(Refusal::new(413, "request body too large"));
    }
    Ok((headers, length))
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_arrives_in_pieces_and_a_refusal_carries_its_status() {
        let mut p = RequestParser::default();
        assert!(matches!(
            p.push(b"GET /abc/?x=1 HTTP/1.1\r\nHo"),
            Ok(Progress::NeedMore)
        ));
        // The request line is known before the headers are complete.
        assert_eq!(p.path(), Some("/abc/"));
        let Ok(Progress::Complete(req)) = p.push(b"st: a\r\n\r\n") else {
            panic!("complete")
        };
        assert_eq!(
            (req.method.as_str(), req.header("host")),
            ("GET", Some("a"))
        );
        let mut p = RequestParser::default();
        assert_eq!(p.push(b"GET / HTTP/9\r\n\r\n").unwrap_err().status, 400);
    }
}
