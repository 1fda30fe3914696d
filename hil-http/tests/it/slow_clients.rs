//! Slow and idle clients against the server: they cannot hold a request
//! open past its deadline, cannot take the slots of those who hold the
//! token, and the oldest of them makes room for a newcomer.

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::time::Duration;

use hil_http::testing::client::{closed_or_answered, wait_for};
use hil_http::{Limits, Occupancy, Request, Response, Server, Service};

/// Serves `/secret/...` to token holders (200) and refuses the rest (403).
struct Secret;

impl Service for Secret {
    fn trusted(&self, path: &str) -> bool {
        path.starts_with("/secret/")
    }

    fn handle(&self, req: &Request) -> Response {
        if self.trusted(&req.path) {
            Response::text(200, "ok")
        } else {
            Response::text(403, "no")
        }
    }
}

fn server(limits: Limits) -> Server {
    Server::start("127.0.0.1:0".parse().unwrap(), Arc::new(Secret), limits).unwrap()
}

/// Reads the status code of the response on `s`.
fn status(s: &mut TcpStream) -> u16 {
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out);
    text.split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"))
}

/// Opens a connection that sends `bytes` and waits until the server
/// counts it in its pools as `expect`.
fn hold(server: &Server, bytes: &[u8], expect: Occupancy) -> TcpStream {
    let mut s = TcpStream::connect(server.addr()).unwrap();
    s.write_all(bytes).unwrap();
    wait_for("the connection to be placed", || {
        server.occupancy() == expect
    });
    s
}

#[test]
fn a_request_still_trickling_at_its_deadline_gets_408() {
    let server = server(Limits {
        request_deadline: Duration::from_millis(500),
        ..Limits::default()
    });
    let mut s = TcpStream::connect(server.addr()).unwrap();
    // A byte every 100 ms: never silent long enough for a per-read timeout,
    // yet never done; the deadline covers the whole request.
    let head = b"GET /secret/ HTTP/1.1\r\nX-Slow: ";
    for i in 0.. {
        assert!(i < 3000, "the server never gave up on the request");
        if s.write_all(&[head.get(i).copied().unwrap_or(b'x')])
            .is_err()
            || closed_or_answered(&mut s)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_eq!(status(&mut s), 408);
}

#[test]
fn a_full_stranger_pool_closes_its_oldest_connection() {
    let server = server(Limits {
        open_slots: 3,
        trusted_slots: 1,
        request_deadline: Duration::from_secs(120),
    });
    let mut idle: Vec<TcpStream> = (1..=3)
        .map(|n| {
            hold(
                &server,
                b"G",
                Occupancy {
                    open: n,
                    trusted: 0,
                },
            )
        })
        .collect();
    // A newcomer is served although the pool is full...
    let mut newcomer = TcpStream::connect(server.addr()).unwrap();
    newcomer
        .write_all(b"GET /elsewhere/ HTTP/1.1\r\n\r\n")
        .unwrap();
    assert_eq!(status(&mut newcomer), 403);
    // ...in the slot of the oldest, which was closed without an answer.
    let mut out = Vec::new();
    idle[0]
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let _ = idle[0].read_to_end(&mut out);
    assert!(out.is_empty(), "{}", String::from_utf8_lossy(&out));
    for s in &mut idle[1..] {
        assert!(!closed_or_answered(s), "a younger connection was closed");
    }
}

#[test]
fn token_holders_have_slots_strangers_cannot_take() {
    let server = server(Limits {
        open_slots: 2,
        trusted_slots: 1,
        request_deadline: Duration::from_secs(120),
    });
    // A token holder whose request line is in, the rest still to come.
    let mut holder = hold(
        &server,
        b"GET /secret/ HTTP/1.1\r\n",
        Occupancy {
            open: 0,
            trusted: 1,
        },
    );
    // Strangers fill their pool, and more keep coming.
    let mut strangers = Vec::new();
    for _ in 0..5 {
        let mut s = TcpStream::connect(server.addr()).unwrap();
        s.write_all(b"GET /x").unwrap();
        strangers.push(s);
    }
    wait_for("the strangers' pool to fill", || {
        server.occupancy().open == 2
    });
    // They took nothing from the token holder, who finishes the request.
    assert_eq!(server.occupancy().trusted, 1);
    assert!(!closed_or_answered(&mut holder));
    holder.write_all(b"Host: a\r\n\r\n").unwrap();
    assert_eq!(status(&mut holder), 200);
    drop(holder);
    wait_for("the token holder's slot to be free", || {
        server.occupancy().trusted == 0
    });
    // A token holder over the trusted pool's size is told to come back.
    // (This one takes the oldest stranger's slot until its request line
    // is in, then moves to the trusted pool.)
    let _second = hold(
        &server,
        b"GET /secret/ HTTP/1.1\r\n",
        Occupancy {
            open: 1,
            trusted: 1,
        },
    );
    let mut third = TcpStream::connect(server.addr()).unwrap();
    third.write_all(b"GET /secret/ HTTP/1.1\r\n\r\n").unwrap();
    assert_eq!(status(&mut third), 503);
}

#[test]
fn zero_limits_are_refused() {
    for limits in [
        Limits {
            open_slots: 0,
            ..Limits::default()
        },
        Limits {
            trusted_slots: 0,
            ..Limits::default()
        },
        Limits {
            request_deadline: Duration::ZERO,
            ..Limits::default()
        },
    ] {
        let err =
            Server::start("127.0.0.1:0".parse().unwrap(), Arc::new(Secret), limits).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::InvalidInput);
    }
}
