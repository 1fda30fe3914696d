//! Slow and idle clients against the web channel: the person's answer
//! arrives while 64 clients trickle bytes (the server's own limits are
//! tested in hil-http).

use crate::web_support;

use std::io::Write;
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use hil_core::{Answer, ArmId, ResponseType};
use hil_http::Occupancy;
use hil_http::testing::client::{closed_or_answered, get, post, same_origin, wait_for};
use web_support::{ask_async, channel, open_id, query};

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
