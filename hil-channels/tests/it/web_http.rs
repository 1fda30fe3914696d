//! The web channel's HTTP side against the loopback server: tokens, hosts,
//! origins, malformed, oversized and concurrent requests, timeouts, and the
//! conformance suite with a scripted person answering over HTTP.

use crate::web_support;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use hil_channels::{WebChannel, WebChannelConfig};
use hil_conformance::check_query_channel;
use hil_core::{Answer, ArmId, QueryChannel, ResponseType};
use web_support::{ask_async, channel, get, open_id, post, query, raw, same_origin};

#[test]
fn tokens_are_required_everywhere() {
    let (_ch, addr, token) = channel(5.0);
    assert_eq!(get(addr, &format!("/{token}/")).0, 200);
    for path in [
        "/",
        "/api/query",
        "/favicon.ico",
        "/0123456789abcdef0123456789abcdef/",
        "/x/api/query",
    ] {
        assert_eq!(get(addr, path).0, 403, "{path}");
    }
    // Change the last character; a fixed suffix would equal the real token
    // whenever the token happens to end in it (1 run in 16).
    let last = if token.ends_with('0') { '1' } else { '0' };
    let wrong = format!("{}{last}", &token[..31]);
    assert_ne!(wrong, token);
    assert_eq!(get(addr, &format!("/{wrong}/api/query")).0, 403);
    assert_eq!(
        post(
            addr,
            &format!("/{wrong}/api/answer"),
            &same_origin(addr),
            "{}"
        )
        .0,
        403
    );
    // The token in a query string is not a token in the path.
    assert_eq!(get(addr, &format!("/?token={token}")).0, 403);
}

#[test]
fn pages_assets_and_methods() {
    let (_ch, addr, token) = channel(5.0);
    let (s, html) = get(addr, &format!("/{token}/"));
    assert_eq!(s, 200);
    assert!(html.contains(r#"<html lang="en">"#) && html.contains("app.js"));
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no external resources"
    );
    assert_eq!(get(addr, &format!("/{token}/app.js")).0, 200);
    assert_eq!(get(addr, &format!("/{token}/app.css")).0, 200);
    let (s, body) = get(addr, &format!("/{token}/api/query"));
    assert_eq!(s, 200);
    assert!(body.contains(r#""state":"waiting""#), "{body}");
    assert_eq!(get(addr, &format!("/{token}/nope")).0, 404);
    assert_eq!(get(addr, &format!("/{token}/api/answer")).0, 405);
    assert_eq!(
        post(
            addr,
            &format!("/{token}/api/query"),
            &same_origin(addr),
            "{}"
        )
        .0,
        405
    );
    // Security headers on every response.
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET /{token}/ HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    for h in [
        "Content-Security-Policy",
        "X-Frame-Options: DENY",
        "Referrer-Policy: no-referrer",
        "Cache-Control: no-store",
    ] {
        assert!(text.contains(h), "{h} missing");
    }
}

#[test]
fn foreign_hosts_and_origins_cannot_answer() {
    let (ch, addr, token) = channel(10.0);
    let asking = ask_async(ch, query(1, ResponseType::Mcq));
    let id = open_id(addr, &token);
    let path = format!("/{token}/api/answer");
    let body = format!(r#"{{"id":{id},"answer":{{"type":"action","arm":3}}}}"#);
    // DNS rebinding: a foreign name for our address.
    let (s, _) = raw(
        addr,
        format!(
            "GET /{token}/api/query HTTP/1.1\r\nHost: evil.example:{}\r\n\r\n",
            addr.port()
        )
        .as_bytes(),
    );
    assert_eq!(s, 403);
    assert_eq!(
        raw(addr, format!("GET /{token}/ HTTP/1.1\r\n\r\n").as_bytes()).0,
        403,
        "no Host"
    );
    // Another origin, no origin, a cross-site fetch, a form post.
    let ct = "Content-Type: application/json\r\n";
    assert_eq!(
        post(
            addr,
            &path,
            &format!("Origin: http://evil.example\r\n{ct}"),
            &body
        )
        .0,
        403
    );
    assert_eq!(
        post(addr, &path, &format!("Origin: null\r\n{ct}"), &body).0,
        403
    );
    assert_eq!(post(addr, &path, ct, &body).0, 403);
    assert_eq!(
        post(
            addr,
            &path,
            &format!("{}Sec-Fetch-Site: cross-site\r\n", same_origin(addr)),
            &body
        )
        .0,
        403
    );
    assert_eq!(
        post(
            addr,
            &path,
            &format!("Origin: http://{addr}\r\nContent-Type: text/plain\r\n"),
            &body
        )
        .0,
        415
    );
    // The question is still open, and the page's own origin can answer it.
    assert_eq!(open_id(addr, &token), id);
    let (s, _) = post(
        addr,
        &path,
        &format!("{}Sec-Fetch-Site: same-origin\r\n", same_origin(addr)),
        &body,
    );
    assert_eq!(s, 200);
    let (_still_serving, r) = asking.join().unwrap();
    assert_eq!(r.answer, Answer::Action { arm: ArmId(3) });
    assert_eq!(r.expert_arm, Some(ArmId(3)));
    assert!(r.response_time_s.unwrap() >= 0.0);
    // Answering again: the question is closed.
    assert_eq!(post(addr, &path, &same_origin(addr), &body).0, 409);
}

#[test]
fn invalid_answers_get_the_right_codes() {
    let (ch, addr, token) = channel(10.0);
    let asking = ask_async(ch, query(1, ResponseType::BoundingBox));
    let id = open_id(addr, &token);
    let path = format!("/{token}/api/answer");
    let h = same_origin(addr);
    let cases = [
        ("{not json", 400),
        (
            &format!(r#"{{"id":{id},"answer":{{"type":"declined"}},"extra":1}}"#) as &str,
            400,
        ),
        (
            &format!(r#"{{"id":{},"answer":{{"type":"declined"}}}}"#, id + 1),
            409,
        ),
        (
            &format!(r#"{{"id":{id},"answer":{{"type":"action","arm":1}}}}"#),
            422,
        ),
        (
            &format!(
                r#"{{"id":{id},"answer":{{"type":"bounding_box","bbox":{{"x0":0.5,"y0":0.1,"x1":0.2,"y1":0.9}}}}}}"#
            ),
            422,
        ),
        (
            &format!(
                r#"{{"id":{id},"answer":{{"type":"bounding_box","bbox":{{"x0":-1,"y0":0.1,"x1":0.2,"y1":0.9}}}}}}"#
            ),
            422,
        ),
        (
            &format!(r#"{{"id":{id},"answer":{{"type":"timed_out"}}}}"#),
            422,
        ),
    ];
    for (body, code) in cases {
        assert_eq!(post(addr, &path, &h, body).0, code, "{body}");
    }
    let ok = format!(
        r#"{{"id":{id},"answer":{{"type":"bounding_box","bbox":{{"x0":0.1,"y0":0.2,"x1":0.3,"y1":0.4}}}}}}"#
    );
    assert_eq!(post(addr, &path, &h, &ok).0, 200);
    let (_, r) = asking.join().unwrap();
    assert!(matches!(r.answer, Answer::BoundingBox { .. }));
    assert_eq!(r.expert_arm, None);
}

#[test]
fn malformed_and_oversized_requests() {
    let (_ch, addr, token) = channel(5.0);
    let cases: Vec<(Vec<u8>, u16)> = vec![
        (b"GARBAGE\r\n\r\n".to_vec(), 400),
        (b"GET\r\n\r\n".to_vec(), 400),
        (format!("GET /{token}/ HTTP/9.9\r\nHost: {addr}\r\n\r\n").into_bytes(), 400),
        (format!("GET /{token}/ HTTP/1.1\r\nno colon here\r\n\r\n").into_bytes(), 400),
        (format!("GET /{token}/ HTTP/1.1\r\nHost: {addr}\r\nHost: {addr}\r\n\r\n").into_bytes(), 400),
        (b"GET /\xff\xfe HTTP/1.1\r\n\r\n".to_vec(), 400),
        (b"GET nopath HTTP/1.1\r\n\r\n".to_vec(), 400),
        (format!("GET /{token}/ HTTP/1.1\r\nHost: {addr}").into_bytes(), 400), // cut short
        (format!("GET /{} HTTP/1.1\r\nHost: {addr}\r\n\r\n", "a".repeat(3000)).into_bytes(), 414),
        (format!("GET /{token}/ HTTP/1.1\r\nHost: {addr}\r\nX-Big: {}\r\n\r\n", "b".repeat(20_000)).into_bytes(), 431),
        (format!("POST /{token}/api/answer HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 1000000\r\n\r\n").into_bytes(), 413),
        (format!("POST /{token}/api/answer HTTP/1.1\r\nHost: {addr}\r\nContent-Length: -5\r\n\r\n").into_bytes(), 400),
        (format!("POST /{token}/api/answer HTTP/1.1\r\nHost: {addr}\r\n\r\n").into_bytes(), 411),
        (format!("POST /{token}/api/answer HTTP/1.1\r\nHost: {addr}\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n").into_bytes(), 501),
        (format!("POST /{token}/api/answer HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 50\r\n\r\nshort").into_bytes(), 400),
    ];
    for (bytes, code) in cases {
        assert_eq!(
            raw(addr, &bytes).0,
            code,
            "{}",
            String::from_utf8_lossy(&bytes[..bytes.len().min(80)])
        );
    }
    // A huge head without an end is cut off, not buffered forever.
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    let junk = vec![b'x'; 64 * 1024];
    let _ = s.write_all(&junk);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    assert!(String::from_utf8_lossy(&out).starts_with("HTTP/1.1 431"));
    // Still serving.
    assert_eq!(get(addr, &format!("/{token}/api/query")).0, 200);
}

#[test]
fn concurrent_requests_are_all_served() {
    let (ch, addr, token) = channel(20.0);
    let token = Arc::new(token);
    let asking = ask_async(ch, query(1, ResponseType::OpenEnded));
    let id = open_id(addr, &token);
    let workers: Vec<_> = (0..40)
        .map(|i| {
            let token = token.clone();
            std::thread::spawn(move || match i % 4 {
                0 => get(addr, &format!("/{token}/api/query")).0,
                1 => get(addr, "/wrong/api/query").0,
                2 => raw(addr, b"BROKEN REQUEST\r\n\r\n").0,
                _ => {
                    post(
                        addr,
                        &format!("/{token}/api/answer"),
                        "Origin: http://evil.example\r\nContent-Type: application/json\r\n",
                        &format!(r#"{{"id":{id},"answer":{{"type":"declined"}}}}"#),
                    )
                    .0
                }
            })
        })
        .collect();
    let codes: Vec<u16> = workers.into_iter().map(|w| w.join().unwrap()).collect();
    for (i, c) in codes.iter().enumerate() {
        let expected = [200, 403, 400, 403][i % 4];
        assert!(*c == expected || *c == 503, "request {i}: {c}");
    }
    assert!(codes.iter().filter(|c| **c != 503).count() >= 20);
    // Exactly one of several simultaneous valid answers wins.
    let answers: Vec<_> = (0..8)
        .map(|i| {
            let token = token.clone();
            std::thread::spawn(move || {
                post(
                    addr,
                    &format!("/{token}/api/answer"),
                    &same_origin(addr),
                    &format!(r#"{{"id":{id},"answer":{{"type":"text","text":"answer {i} TV0"}}}}"#),
                )
                .0
            })
        })
        .collect();
    let codes: Vec<u16> = answers.into_iter().map(|w| w.join().unwrap()).collect();
    assert_eq!(codes.iter().filter(|c| **c == 200).count(), 1, "{codes:?}");
    assert!(codes.iter().all(|c| *c == 200 || *c == 409), "{codes:?}");
    let (_, r) = asking.join().unwrap();
    assert_eq!(r.expert_arm, Some(ArmId(2)));
}

#[test]
fn no_answer_in_time_times_out_and_says_so() {
    let (mut ch, addr, token) = channel(0.3);
    let r = ch.ask(&query(1, ResponseType::Mcq)).unwrap();
    assert_eq!(r.answer, Answer::TimedOut);
    assert_eq!(r.expert_arm, None);
    assert_eq!(r.response_time_s, Some(0.3));
    let (_, body) = get(addr, &format!("/{token}/api/query"));
    assert!(
        body.contains("no answer in time") || body.contains("No answer in time"),
        "{body}"
    );
}

#[test]
fn bad_configs_are_refused() {
    let refused = |config: WebChannelConfig| match WebChannel::start(config) {
        Err(hil_core::HilError::InvalidParameter { name, .. }) => name,
        other => panic!("{other:?}"),
    };
    for timeout_s in [0.0, -1.0, f64::NAN] {
        let config = WebChannelConfig {
            timeout_s,
            ..Default::default()
        };
        assert_eq!(refused(config), "timeout_s");
    }
    let config = WebChannelConfig {
        allowed_hosts: vec!["bad host/".into()],
        ..Default::default()
    };
    assert_eq!(refused(config), "allowed_hosts");
    // The port is taken: the error says which address.
    let (taken, addr, _) = channel(5.0);
    let err = WebChannel::start(WebChannelConfig {
        port: addr.port(),
        ..Default::default()
    })
    .unwrap_err();
    match err {
        hil_core::HilError::Channel { channel, why, .. } => {
            assert_eq!(channel, "web");
            assert!(why.contains(&addr.to_string()), "{why}");
        }
        other => panic!("{other:?}"),
    }
    drop(taken);
}

/// A person who answers every question over HTTP as the page would.
fn scripted_person(addr: SocketAddr, token: String, n: usize) -> JoinHandle<()> {
    std::thread::spawn(move || {
        for i in 0..n {
            let id = open_id(addr, &token);
            let (_, body) = get(addr, &format!("/{token}/api/query"));
            let v: serde_json::Value = serde_json::from_str(&body).unwrap();
            let answer = if i % 5 == 4 {
                r#"{"type":"declined"}"#.to_string()
            } else {
                match v["kind"]["response"].as_str().unwrap() {
                    "mcq" => format!(r#"{{"type":"action","arm":{}}}"#, i % 6),
                    "bounding_box" => {
                        r#"{"type":"bounding_box","bbox":{"x0":0.1,"y0":0.1,"x1":0.5,"y1":0.5}}"#
                            .into()
                    }
                    _ => r#"{"type":"text","text":"use TA90"}"#.into(),
                }
            };
            let (s, _) = post(
                addr,
                &format!("/{token}/api/answer"),
                &same_origin(addr),
                &format!(r#"{{"id":{id},"answer":{answer}}}"#),
            );
            assert_eq!(s, 200);
        }
    })
}

#[test]
fn conforms_with_a_person_answering_over_http() {
    let (mut ch, addr, token) = channel(20.0);
    let person = scripted_person(addr, token, 18);
    check_query_channel(&mut ch, 18).unwrap();
    person.join().unwrap();
}

#[test]
fn item_pictures_are_served_for_the_open_question_only() {
    let dir = std::env::temp_dir().join(format!("hil-web-images-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("cantaloupe.png"), "PNGDATA").unwrap();
    std::fs::write(dir.join("secret.png"), "SECRET").unwrap();
    let ch = WebChannel::start(WebChannelConfig {
        timeout_s: 10.0,
        images: Some(dir.clone()),
        ..Default::default()
    })
    .unwrap();
    let addr = ch.addr();
    let token = web_support::token_of(ch.url());
    let asking = ask_async(ch, query(1, ResponseType::Mcq));
    let id = open_id(addr, &token);
    let (_, body) = get(addr, &format!("/{token}/api/query"));
    let v: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(v["image"], format!("image/{id}"));
    let (s, bytes) = get(addr, &format!("/{token}/image/{id}"));
    assert_eq!((s, bytes.as_str()), (200, "PNGDATA"));
    assert_eq!(get(addr, &format!("/{token}/image/{}", id + 1)).0, 404);
    assert_eq!(get(addr, &format!("/{token}/image/../secret.png")).0, 404);
    assert_eq!(get(addr, &format!("/x/image/{id}")).0, 403);
    let (s, _) = post(
        addr,
        &format!("/{token}/api/answer"),
        &same_origin(addr),
        &format!(r#"{{"id":{id},"answer":{{"type":"declined"}}}}"#),
    );
    assert_eq!(s, 200);
    let (mut ch, r) = asking.join().unwrap();
    assert_eq!(r.answer, Answer::Declined);
    // Labels that are not plain names never map to a file.
    let mut q = query(2, ResponseType::Mcq);
    q.item.label = "../secret".into();
    let person = std::thread::spawn(move || {
        let id = open_id(addr, &token);
        let (_, body) = get(addr, &format!("/{token}/api/query"));
        let v: serde_json::Value = serde_json::from_str(&body).unwrap();
        assert!(v["image"].is_null(), "{v}");
        post(
            addr,
            &format!("/{token}/api/answer"),
            &same_origin(addr),
            &format!(r#"{{"id":{id},"answer":{{"type":"declined"}}}}"#),
        )
        .0
    });
    ch.ask(&q).unwrap();
    assert_eq!(person.join().unwrap(), 200);
    drop(ch);
    match WebChannel::start(WebChannelConfig {
        images: Some(dir.join("missing")),
        ..Default::default()
    }) {
        Err(hil_core::HilError::InvalidParameter { name, value, .. }) => {
            assert_eq!(name, "images");
            assert!(value.ends_with("missing"), "{value}");
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_printed_urls_are_addresses_the_server_listens_on() {
    // Default bind: one loopback URL, and the endpoint says the same.
    let (ch, addr, token) = channel(5.0);
    assert_eq!(
        ch.urls(),
        [format!("http://127.0.0.1:{}/{token}/", addr.port())]
    );
    assert_eq!(ch.endpoint().unwrap(), ch.url());
    drop(ch);
    // All interfaces: the machine's addresses, never 0.0.0.0, each serving
    // the page (no network needed: they are this machine's own).
    let ch = WebChannel::start(WebChannelConfig {
        bind: "0.0.0.0".parse().unwrap(),
        ..Default::default()
    })
    .unwrap();
    let urls = ch.urls().to_vec();
    assert!(!urls.is_empty());
    assert_eq!(ch.endpoint().unwrap().lines().collect::<Vec<_>>(), urls);
    assert_eq!(ch.url(), urls[0]);
    let token = web_support::token_of(ch.url());
    for url in &urls {
        let host = url
            .strip_prefix("http://")
            .and_then(|u| u.split('/').next())
            .unwrap();
        let at: SocketAddr = host.parse().unwrap();
        assert!(!at.ip().is_unspecified(), "{url}");
        assert_eq!(at.port(), ch.addr().port(), "{url}");
        assert_eq!(*url, format!("http://{at}/{token}/"));
        let (s, html) = get(at, &format!("/{token}/"));
        assert_eq!(s, 200, "{url}");
        assert!(html.contains("app.js"), "{url}");
    }
    // Addresses other devices can use come first; loopback only last.
    let loopback_at = urls.iter().position(|u| u.contains("//127."));
    assert!(loopback_at.is_none_or(|i| i == urls.len() - 1), "{urls:?}");
}

#[test]
fn unreadable_pictures_are_errors_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("hil-web-bad-images-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // Over the asset limit (sparse: no disk space used), and not a file.
    let big = dir.join("cantaloupe.png");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(hil_core::files::limits::ASSET + 1)
        .unwrap();
    std::fs::create_dir(dir.join("banana.jpg")).unwrap();
    let mut ch = WebChannel::start(WebChannelConfig {
        timeout_s: 5.0,
        images: Some(dir.clone()),
        ..Default::default()
    })
    .unwrap();
    let mut q = query(1, ResponseType::Mcq);
    for (label, file) in [("cantaloupe", "cantaloupe.png"), ("banana", "banana.jpg")] {
        q.item.label = label.into();
        match ch.ask(&q) {
            Err(hil_core::HilError::Io { path, .. }) => assert_eq!(path, dir.join(file)),
            other => panic!("{label}: {other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
