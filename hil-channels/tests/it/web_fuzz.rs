//! Fuzzing the web channel's request parser (property tests, stable Rust,
//! a few seconds in a debug build): random bytes, request-shaped input with
//! truncations, huge headers, bad `Content-Length`s and non-UTF-8 bytes.
//! Nothing panics, every refusal has one of the parser's status codes, the
//! result does not depend on how the bytes were split into reads, the
//! parser's buffer stays bounded, and the
//! live server answers each input with a status from a bounded set and
//! keeps serving.

use crate::web_support;

use proptest::prelude::*;

use hil_http::parse::{Progress, RequestParser};
use hil_http::{MAX_BODY_BYTES, MAX_HEAD_BYTES};
use web_support::{channel, get, raw};

/// What the parser made of an input, in a comparable form.
#[derive(Debug, PartialEq)]
enum Outcome {
    /// Still incomplete; what closing the connection now would answer.
    NeedMore(Option<u16>),
    Complete {
        method: String,
        path: String,
        headers: Vec<(String, String)>,
        body: Vec<u8>,
    },
    Refused(u16, &'static str),
}

/// Feeds `bytes` to a parser in pieces ending at `cuts` (sorted positions),
/// stopping at the first request or refusal, as a server does.
fn parse(bytes: &[u8], cuts: &[usize]) -> Outcome {
    let mut parser = RequestParser::default();
    let mut from = 0;
    for end in cuts.iter().copied().chain([bytes.len()]) {
        let end = end.clamp(from, bytes.len());
        match parser.push(&bytes[from..end]) {
            Ok(Progress::NeedMore) => {
                // Memory stays bounded however much is sent.
                assert!(parser.buffered() <= MAX_HEAD_BYTES + 4 + MAX_BODY_BYTES);
                from = end;
            }
            Ok(Progress::Complete(req)) => {
                let mut headers: Vec<_> = req.headers.into_iter().collect();
                headers.sort();
                return Outcome::Complete {
                    method: req.method,
                    path: req.path,
                    headers,
                    body: req.body,
                };
            }
            Err(r) => return Outcome::Refused(r.status, r.why),
        }
    }
    Outcome::NeedMore(parser.end_of_input().map(|r| r.status))
}

/// The parser's own refusals.
const PARSER_CODES: [u16; 6] = [400, 411, 413, 414, 431, 501];

/// Every status the channel answers a single request with.
const SERVER_CODES: [u16; 13] = [
    200, 400, 403, 404, 405, 409, 411, 413, 414, 415, 422, 431, 501,
];

/// Request-shaped input: a request line, headers and a body, each drawn
/// from valid and invalid pieces, then possibly cut short or given a
/// non-UTF-8 byte. `TOKEN` and `HOST` are placeholders for the live
/// server's token and address.
fn request() -> impl Strategy<Value = Vec<u8>> {
    let method = prop_oneof![
        Just("GET".to_string()),
        Just("POST".to_string()),
        Just("get".to_string()),
        Just(String::new()),
        "[A-Z]{1,8}",
    ];
    let target = prop_oneof![
        Just("/TOKEN/".to_string()),
        Just("/TOKEN/api/query".to_string()),
        Just("/TOKEN/api/answer".to_string()),
        Just("/TOKEN/image/0".to_string()),
        Just("/".to_string()),
        "/[ -~]{0,40}",
        (1usize..4000).prop_map(|n| format!("/{}", "a".repeat(n))),
    ];
    let version = prop_oneof![
        3 => Just("HTTP/1.1"),
        1 => Just("HTTP/1.0"),
        1 => Just("HTTP/2"),
        1 => Just(""),
    ];
    let length = prop_oneof![
        (0usize..64).prop_map(|n| n.to_string()),
        Just("-5".to_string()),
        Just("+5".to_string()),
        Just(" 7".to_string()),
        Just(String::new()),
        Just("99999999999999999999999999".to_string()),
        Just((MAX_BODY_BYTES + 1).to_string()),
        "[0-9a-z ]{0,6}",
    ];
    let header = prop_oneof![
        Just(("Host".to_string(), "HOST".to_string())),
        Just(("Origin".to_string(), "http://HOST".to_string())),
        Just(("Content-Type".to_string(), "application/json".to_string())),
        length.prop_map(|v| ("Content-Length".to_string(), v)),
        Just(("Transfer-Encoding".to_string(), "chunked".to_string())),
        (1usize..(MAX_HEAD_BYTES + 2000)).prop_map(|n| ("X-Big".to_string(), "b".repeat(n))),
        ("[!-~]{0,12}", "[ -~]{0,24}"),
    ];
    let body = prop_oneof![
        Just(br#"{"id":0,"answer":{"type":"declined"}}"#.to_vec()),
        prop::collection::vec(any::<u8>(), 0..128),
    ];
    (
        method,
        target,
        version,
        prop::collection::vec(header, 0..6),
        body,
        any::<prop::sample::Index>(),
        prop::option::of((any::<prop::sample::Index>(), 0x80u8..=0xff)),
        any::<bool>(),
    )
        .prop_map(
            |(method, target, version, headers, body, cut, junk, truncate)| {
                let mut bytes = format!("{method} {target} {version}\r\n").into_bytes();
                for (name, value) in headers {
                    bytes.extend_from_slice(format!("{name}: {value}\r\n").as_bytes());
                }
                bytes.extend_from_slice(b"\r\n");
                bytes.extend_from_slice(&body);
                if let Some((at, byte)) = junk {
                    bytes.insert(at.index(bytes.len() + 1), byte);
                }
                if truncate {
                    bytes.truncate(cut.index(bytes.len() + 1));
                }
                bytes
            },
        )
}

/// Any bytes, or request-shaped ones.
fn input() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![prop::collection::vec(any::<u8>(), 0..2048), request()]
}

/// Checks what the parser may return for any input.
fn check_outcome(outcome: &Outcome) {
    match outcome {
        Outcome::Refused(status, _) => assert!(PARSER_CODES.contains(status), "{outcome:?}"),
        Outcome::NeedMore(status) => assert!(status.is_none_or(|s| s == 400), "{outcome:?}"),
        Outcome::Complete { path, body, .. } => {
            assert!(path.starts_with('/'), "{outcome:?}");
            assert!(body.len() <= MAX_BODY_BYTES, "{outcome:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn the_parser_never_panics_and_ignores_how_bytes_are_split(
        bytes in input(),
        cuts in prop::collection::vec(any::<prop::sample::Index>(), 0..24),
    ) {
        let whole = parse(&bytes, &[]);
        check_outcome(&whole);
        let mut cuts: Vec<usize> = cuts.iter().map(|i| i.index(bytes.len() + 1)).collect();
        cuts.sort_unstable();
        prop_assert_eq!(parse(&bytes, &cuts), whole);
        // One byte at a time, as a trickling client sends it.
        if bytes.len() <= 4096 {
            let every: Vec<usize> = (1..bytes.len()).collect();
            prop_assert_eq!(parse(&bytes, &every), parse(&bytes, &[]));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn the_server_answers_any_input_with_a_bounded_status(
        inputs in prop::collection::vec(input(), 1..4),
    ) {
        let (_ch, addr, token) = channel(5.0);
        for bytes in inputs {
            if bytes.is_empty() {
                continue; // nothing sent, nothing to answer
            }
            let bytes = replace(&bytes, b"TOKEN", token.as_bytes());
            let bytes = replace(&bytes, b"HOST", addr.to_string().as_bytes());
            let (status, _) = raw(addr, &bytes);
            prop_assert!(SERVER_CODES.contains(&status), "{} for {:?}", status,
                String::from_utf8_lossy(&bytes[..bytes.len().min(200)]));
        }
        prop_assert_eq!(get(addr, &format!("/{token}/api/query")).0, 200);
    }
}

/// `bytes` with every `from` replaced by `to`.
fn replace(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            out.extend_from_slice(to);
            i += from.len();
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}
