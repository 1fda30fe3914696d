//! Helpers shared by the web channel's HTTP test suites: a loopback
//! channel, a query, and a person polling for it (the raw HTTP client is
//! `hil_http::testing::client`, re-exported here).

// Each suite uses its own subset of these.
#![allow(dead_code)]

use std::net::SocketAddr;
use std::thread::JoinHandle;
use std::time::Duration;

use hil_channels::{WebChannel, WebChannelConfig};
use hil_core::{ArmId, Context, Item, Query, QueryChannel, QueryKind, Response, ResponseType};
pub use hil_http::testing::client::{get, post, raw, same_origin, token_of};

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
