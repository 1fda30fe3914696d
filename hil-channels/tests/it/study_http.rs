//! The study server over plain HTTP: tokens and origins, refused and
//! repeated submissions, the data folder's lock and design, a cut-short log
//! line, the task clock stopping while the participant is away, and
//! located config errors.

use crate::web_support;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use hil_channels::study::{StudyConfig, StudyServer, export};
use hil_core::HilError;
use hil_workload::study::Population;
use serde_json::{Value, json};
use web_support::{get, post, same_origin, token_of};

const CONFIG: &str = "[design]\ndifficulties = [\"easy\"]\ndistractions = [\"easy\"]\nintervals_min = [2]\nbaselines = [\"hard\"]\nbaseline_position = \"last\"\ntime_scale = 60\n";

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-study-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn config(extra: &str) -> StudyConfig {
    StudyConfig::parse(&format!("{CONFIG}{extra}"), "study.toml".as_ref()).unwrap()
}

fn state(addr: SocketAddr, token: &str) -> Value {
    let (s, body) = get(addr, &format!("/{token}/api/state"));
    assert_eq!(s, 200, "{body}");
    serde_json::from_str(&body).unwrap()
}

fn send(addr: SocketAddr, token: &str, what: &str, body: Value) -> (u16, Value) {
    let (s, b) = post(
        addr,
        &format!("/{token}/api/{what}"),
        &same_origin(addr),
        &body.to_string(),
    );
    (s, serde_json::from_str(&b).unwrap_or(Value::Null))
}

fn until(addr: SocketAddr, token: &str, pred: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let v = state(addr, token);
        if pred(&v) {
            return v;
        }
        assert!(Instant::now() < deadline, "{v}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn tlx(v: u8) -> Value {
    json!({"mental": v, "temporal": 1, "performance": 5, "effort": 2, "frustration": 1})
}

#[test]
fn tokens_origins_and_repeated_or_bad_submissions() {
    let dir = temp_dir("http");
    let server = StudyServer::start(config(""), &dir).unwrap();
    let addr = server.addr();
    let (_, urls) = server.enrol(Population::NoLimitation).unwrap();
    let token = token_of(&urls[0]);
    let researcher = token_of(&server.researcher_urls()[0]);

    // Without or with a wrong token, nothing; the researcher's token is not a participant's.
    assert_eq!(get(addr, "/").0, 403);
    assert_eq!(
        get(addr, "/0123456789abcdef0123456789abcdef/api/state").0,
        403
    );
    assert_eq!(get(addr, &format!("/{researcher}/api/state")).0, 404);
    let (s, body) = get(addr, &format!("/{researcher}/api/progress"));
    assert_eq!(s, 200);
    assert!(!body.contains(&"name".to_string()), "{body}");
    // Answers only from the page's own origin.
    let start = json!({"condition": "c01"}).to_string();
    let (s, _) = post(
        addr,
        &format!("/{token}/api/start"),
        "Content-Type: application/json\r\n",
        &start,
    );
    assert_eq!(s, 403);
    let (s, _) = post(
        addr,
        &format!("/{token}/api/start"),
        "Origin: http://evil.example\r\nContent-Type: application/json\r\n",
        &start,
    );
    assert_eq!(s, 403);
    // The baselines come last here: the query condition first.
    let v = state(addr, &token);
    assert_eq!(
        (v["phase"].as_str(), v["condition"]["id"].as_str()),
        (Some("intro"), Some("c01"))
    );
    assert_eq!(
        send(addr, &token, "start", json!({"condition": "baseline_hard"})).0,
        409
    );
    assert_eq!(
        send(addr, &token, "start", json!({"condition": "c01"})).0,
        200
    );
    // An addition answered, one answered again (not logged twice).
    let v = state(addr, &token);
    let (a, b) = (
        v["distraction"]["a"].as_u64().unwrap(),
        v["distraction"]["b"].as_u64().unwrap(),
    );
    let sum = json!({"condition": "c01", "index": 0, "text": (a + b).to_string()});
    assert_eq!(
        send(addr, &token, "distraction", sum.clone()).1["already_saved"],
        json!(false)
    );
    assert_eq!(
        send(addr, &token, "distraction", sum).1["already_saved"],
        json!(true)
    );
    // The first query (at 1 study minute = 1 s).
    let v = until(addr, &token, |v| v["query"].is_object());
    let kind = v["query"]["kind"].as_str().unwrap().to_string();
    // A picture of the open query is served; of another, not.
    let (s, svg) = get(
        addr,
        &format!("/{token}/{}", v["query"]["pictures"][0].as_str().unwrap()),
    );
    assert_eq!(s, 200);
    assert!(svg.starts_with("<svg") && !svg.contains("<script"));
    assert_eq!(get(addr, &format!("/{token}/image/c01/1/0")).0, 404);
    // A survey before the answer, an answer of the wrong kind, an answer to
    // a query that is not open: refused, nothing logged.
    assert_eq!(
        send(
            addr,
            &token,
            "survey",
            json!({"condition": "c01", "query": 0, "tlx": tlx(2)})
        )
        .0,
        409
    );
    let wrong = if kind == "open_ended" {
        json!({"type": "label", "label": "grape"})
    } else {
        json!({"type": "text", "text": "hm"})
    };
    assert_eq!(
        send(
            addr,
            &token,
            "answer",
            json!({"condition": "c01", "query": 0, "answer": wrong})
        )
        .0,
        422
    );
    assert_eq!(
        send(
            addr,
            &token,
            "answer",
            json!({"condition": "c01", "query": 1, "answer": {"type": "declined"}})
        )
        .0,
        409
    );
    let ok = send(
        addr,
        &token,
        "answer",
        json!({"condition": "c01", "query": 0, "answer": {"type": "declined"}}),
    );
    assert_eq!(ok.0, 200);
    let again = send(
        addr,
        &token,
        "answer",
        json!({"condition": "c01", "query": 0, "answer": {"type": "declined"}}),
    );
    assert_eq!(again.1["already_saved"], json!(true));
    // A TLX answer outside 1..=5 is refused; a good one saved once.
    let bad = json!({"condition": "c01", "query": 0, "tlx": {"mental": 6, "temporal": 1, "performance": 1, "effort": 1, "frustration": 1}});
    assert_eq!(send(addr, &token, "survey", bad).0, 422);
    let good = json!({"condition": "c01", "query": 0, "tlx": tlx(4)});
    assert_eq!(
        send(addr, &token, "survey", good.clone()).1["already_saved"],
        json!(false)
    );
    assert_eq!(
        send(addr, &token, "survey", good).1["already_saved"],
        json!(true)
    );

    // A second server on the same folder is refused while this one runs.
    assert!(StudyServer::start(config(""), &dir).is_err());
    drop(server);
    // Another design on the same folder is refused.
    let other = StudyConfig::parse(
        &CONFIG.replace("intervals_min = [2]", "intervals_min = [1]"),
        "s.toml".as_ref(),
    )
    .unwrap();
    assert!(matches!(
        StudyServer::start(other, &dir),
        Err(HilError::InvalidInput { .. })
    ));
    // A line cut short by a crash is dropped on reopening; the rest stays.
    let log = dir.join("participants/p001.jsonl");
    let lines_before = std::fs::read_to_string(&log).unwrap().lines().count();
    let mut text = std::fs::read_to_string(&log).unwrap();
    text.push_str("{\"seq\": 99, \"unix_ms\": 1, \"event\": \"survey_sub");
    std::fs::write(&log, text).unwrap();
    let server = StudyServer::start(config(""), &dir).unwrap();
    assert_eq!(
        std::fs::read_to_string(&log).unwrap().lines().count(),
        lines_before
    );
    let urls = server.participant_urls("p001").unwrap();
    let v = state(server.addr(), &token_of(&urls[0]));
    assert_eq!(v["phase"], "task");
    drop(server);
    // The export has the one query survey (the baseline is not done yet).
    let study = export(&dir).unwrap();
    assert_eq!(study.records().len(), 1);
    let r = &study.records()[0];
    assert_eq!((r.participant.as_str(), r.tlx.mental), ("p001", 4));
    assert!(r.query_time_s >= 60.0, "{}", r.query_time_s);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_task_clock_stops_while_the_participant_is_away() {
    let dir = temp_dir("away");
    let server = StudyServer::start(config("[server]\naway_after_s = 0.3\n"), &dir).unwrap();
    let addr = server.addr();
    let (_, urls) = server.enrol(Population::OccupationalTherapist).unwrap();
    let token = token_of(&urls[0]);
    assert_eq!(
        send(addr, &token, "start", json!({"condition": "c01"})).0,
        200
    );
    std::thread::sleep(Duration::from_millis(100));
    let t0 = state(addr, &token)["task_s"].as_f64().unwrap();
    assert!(t0 > 0.0, "the clock runs while the page asks");
    // Away for 1 s (60 study seconds at time_scale 60): not counted.
    std::thread::sleep(Duration::from_millis(1000));
    let t1 = state(addr, &token)["task_s"].as_f64().unwrap();
    assert_eq!(t1, t0, "the clock stood still while away");
    let log = std::fs::read_to_string(dir.join("participants/p001.jsonl")).unwrap();
    assert!(log.contains("\"event\":\"resumed\""), "{log}");
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn config_errors_name_the_file_line_and_key() {
    let cases = [
        ("[design]\nintervals_min = [3]\n", 2, "design.intervals_min"),
        ("[design]\ntime_scale = 0\n", 2, "design.time_scale"),
        ("[design]\nbaselines = [\"none\"]\n", 2, "design.baselines"),
        (
            "[design]\ncondition_min = 1\nfirst_query_min = 1\n",
            3,
            "design.first_query_min",
        ),
        ("[server]\naway_after_s = -1\n", 2, "server.away_after_s"),
        (
            "[materials]\naddition_max = 5\n",
            2,
            "materials.addition_max",
        ),
        ("[design]\ncolour = \"red\"\n", 2, "design.colour"),
    ];
    for (text, line, field) in cases {
        let e = StudyConfig::parse(text, "study.toml".as_ref()).unwrap_err();
        let HilError::Config(c) = &e else {
            panic!("{text}: {e:?}")
        };
        assert_eq!(
            (c.line, c.field.as_deref()),
            (line, Some(field)),
            "{text}: {e}"
        );
    }
    // The default is the paper's design.
    let d = hil_channels::study::Design::new(StudyConfig::default().design).unwrap();
    assert_eq!(d.conditions().len(), 14);
}
