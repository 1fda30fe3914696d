//! Slow and idle clients against the web channel's server: they cannot
//! hold a request open past its deadline, cannot starve the slots of the
//! person who holds the token, and the person's answer arrives while 64 of
//! them trickle bytes.

use crate::web_support;

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::web::http::{Limits, Occupancy, Request, Response, Server, Service};
use hil_core::{Answer, ArmId, ResponseType};
use web_support::{ask_async, channel, get, open_id, post, query, same_origin};

/// Waits (polling) until `cond` holds; panics after a minute, so that a
/// broken server fails the test instead of hanging it.
fn wait_for(what: &str, mut cond: impl FnMut() -> bool) {
    let give_up = Instant::now() + Duration::from_secs(60);
    while !cond() {
        assert!(Instant::now() < give_up, "gave up waiting for {what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Whether the server has closed `s` or answered on it (without blocking).
fn closed_or_answered(s: &mut TcpStream) -> bool {
    s.set_nonblocking(true).unwrap();
    let mut byte = [0u8; 1];
    let done = match s.read(&mut byte) {
        Ok(_) => true, // a response, or the end of the stream
        Err(e) => e.kind() != ErrorKind::WouldBlock,
    };
    s.set_nonblocking(false).unwrap();
    done
}

/// A slowloris client: connects, sends a request one byte every
/// `every`, and reconnects whenever the server gives up on it, until
/// `stop`. Counts its connections in `connects`.
fn trickler(
    addr: SocketAddr,
    every: Duration,
    stop: Arc<AtomicBool>,
    connects: Arc<AtomicUsize>,
) -> JoinHandle<()> {
    std::thread::spawn(move || {
        let request = b"GET /not-the-token/ HTTP/1.1\r\nHost: x\r\nX-Padding: ";
        while !stop.load(Ordering::SeqCst) {
            let Ok(mut s) = TcpStream::connect(addr) else {
                std::thread::sleep(Duration::from_millis(100));
                continue;
            };
            connects.fetch_add(1, Ordering::SeqCst);
            let mut sent = 0;
            'connection: loop {
                let byte = request.get(sent).copied().unwrap_or(b'x');
                if s.write_all(&[byte]).is_err() {
                    break;
                }
                sent += 1;
                // Sleep in small steps, to notice `stop` and a closed
                // connection soon.
                let next = Instant::now() + every;
                while Instant::now() < next {
                    if stop.load(Ordering::SeqCst) || closed_or_answered(&mut s) {
                        break 'connection;
                    }
                    std::thread::sleep(Duration::from_millis(50));
                }
            }
            // Real attackers reconnect at once; a pause keeps the test light.
            std::thread::sleep(Duration::from_millis(100));
        }
    })
}

#[test]
fn the_person_answers_while_64_clients_trickle_bytes() {
    let (ch, addr, token) = channel(15.0);
    let stop = Arc::new(AtomicBool::new(false));
    let connects = Arc::new(AtomicUsize::new(0));
    let strangers: Vec<_> = (0..64)
        .map(|_| trickler(addr, Duration::from_secs(5), stop.clone(), connects.clone()))
        .collect();
    // Every slot for strangers is taken (this locked the person out).
    wait_for("64 trickling connections", || ch.occupancy().open == 64);

    let started = Instant::now();
    let (s, html) = get(addr, &format!("/{token}/"));
    assert_eq!(s, 200);
    assert!(html.contains("app.js"));
    let page_latency = started.elapsed();

    let asking = ask_async(ch, query(1, ResponseType::Mcq));
    let id = open_id(addr, &token); // polls the page's API, each poll 200
    let answered = Instant::now();
    let (s, _) = post(
        addr,
        &format!("/{token}/api/answer"),
        &same_origin(addr),
        &format!(r#"{{"id":{id},"answer":{{"type":"action","arm":4}}}}"#),
    );
    let answer_latency = answered.elapsed();
    assert_eq!(s, 200);
    let (ch, r) = asking.join().unwrap();
    assert_eq!(r.answer, Answer::Action { arm: ArmId(4) }, "not timed out");
    assert_eq!(r.expert_arm, Some(ArmId(4)));
    // Measured, not asserted (speed belongs in a benchmark): run with
    // --nocapture to see it.
    let Occupancy { open, trusted } = ch.occupancy();
    eprintln!(
        "under 64 trickling clients: page {:.1} ms, answer {:.1} ms, question answered \
         {:.1} ms after it was asked; {open} strangers and {trusted} token holders \
         connected at the end",
        page_latency.as_secs_f64() * 1e3,
        answer_latency.as_secs_f64() * 1e3,
        r.response_time_s.unwrap() * 1e3,
    );
    stop.store(true, Ordering::SeqCst);
    for s in strangers {
        s.join().unwrap();
    }
    assert!(connects.load(Ordering::SeqCst) >= 64);
}

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
