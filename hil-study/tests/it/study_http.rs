//! The study server over plain HTTP: tokens and origins, refused and
//! repeated submissions, the data folder's lock and design, a cut-short log
//! line, the task clock stopping while the participant is away, and
//! located config errors.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use hil_core::HilError;
use hil_http::testing::client::{get, post, same_origin, token_of};
use hil_study::{StudyConfig, StudyServer, export};
use hil_workload::study::Population;
use serde_json::{Value, json};

const CONFIG: &str = "[design]\ndifficulties = [\"easy\"]\ndistractions = [\"easy\"]\nintervals_min = [2]\nbaselines = [\"hard\"]\nbaseline_position = \"last\"\ntime_scale = 60\n";

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-study-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Waits until nothing holds the data folder's lock. A dropped server has
/// closed its lock file, but a child process that another test forked at
/// that moment shares the open file until it execs, and holds the lock
/// that long.
fn wait_for_lock_release(dir: &Path) {
    let path = dir.join("study.lock");
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let file = std::fs::File::open(&path).unwrap();
        // Dropping `file` releases the lock it took. (`File::try_lock` is
        // what the server locks with; see its note on the MSRV.)
        #[allow(clippy::incompatible_msrv)]
        let free = file.try_lock().is_ok();
        if free {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "{} stayed locked",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
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
    // Re-sent with other contents, a saved survey, answer or sum is not
    // confirmed: 409, saying what was saved there.
    let (s, v) = send(
        addr,
        &token,
        "survey",
        json!({"condition": "c01", "query": 0, "tlx": tlx(2)}),
    );
    assert_eq!(s, 409, "{v}");
    let why = v["error"].as_str().unwrap();
    assert!(
        why.contains("the survey after query 0 of condition `c01` was saved already")
            && why.contains(r#""mental":4"#),
        "{why}"
    );
    let (s, v) = send(
        addr,
        &token,
        "answer",
        json!({"condition": "c01", "query": 0, "answer": {"type": "text", "text": "other"}}),
    );
    assert_eq!(s, 409, "{v}");
    assert!(
        v["error"]
            .as_str()
            .unwrap()
            .contains(r#"{"type":"declined"}"#),
        "{v}"
    );
    let other_sum = json!({"condition": "c01", "index": 0, "text": (a + b + 1).to_string()});
    assert_eq!(send(addr, &token, "distraction", other_sum).0, 409);

    // A second server on the same folder is refused while this one runs.
    assert!(StudyServer::start(config(""), &dir).is_err());
    drop(server);
    wait_for_lock_release(&dir);
    // Another design on the same folder is refused.
    let other = StudyConfig::parse(
        &CONFIG.replace("intervals_min = [2]", "intervals_min = [1]"),
        "s.toml".as_ref(),
    )
    .unwrap();
    let e = StudyServer::start(other, &dir).unwrap_err();
    assert!(matches!(e, HilError::InvalidInput { .. }), "{e:?}");
    // It says which field differs, with both values, and how to serve the
    // folder again.
    let why = e.to_string();
    assert!(
        why.contains("`intervals_min` is [2] in the folder, [1] here"),
        "{why}"
    );
    assert!(why.contains("--config FILE"), "{why}");
    assert!(!why.contains("time_scale"), "only what differs: {why}");
    // A line cut short by a crash is dropped on reopening; the rest stays,
    // and the restart is logged with what was replayed.
    let log = dir.join("participants/p001.jsonl");
    let lines_before = std::fs::read_to_string(&log).unwrap().lines().count();
    let mut text = std::fs::read_to_string(&log).unwrap();
    text.push_str("{\"seq\": 99, \"unix_ms\": 1, \"event\": \"survey_sub");
    std::fs::write(&log, text).unwrap();
    let server = StudyServer::start(config(""), &dir).unwrap();
    let after = std::fs::read_to_string(&log).unwrap();
    assert_eq!(after.lines().count(), lines_before + 1, "{after}");
    let resumed: Value = serde_json::from_str(after.lines().last().unwrap()).unwrap();
    assert_eq!(resumed["seq"], json!(lines_before));
    assert!(resumed["unix_ms"].as_u64().unwrap() > 0, "{resumed}");
    assert_eq!(
        (&resumed["event"], &resumed["condition"]),
        (&json!("resumed"), &json!("c01"))
    );
    assert_eq!(
        resumed["replayed"],
        json!({"lines": lines_before, "dropped_cut_short_line": true})
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
    // A repeated entry is shown as the config spells it.
    let e = StudyConfig::parse(
        "[design]\ndifficulties = [\"easy\", \"hard\", \"easy\"]\n",
        "study.toml".as_ref(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains(r#"lists "easy" twice"#), "{e}");
    assert!(!e.contains("Easy"), "no Rust names: {e}");
    // The default is the paper's design.
    let d = hil_study::Design::new(StudyConfig::default().design).unwrap();
    assert_eq!(d.conditions().len(), 14);
}

#[test]
fn a_log_line_about_another_condition_is_refused_in_plain_words() {
    let dir = temp_dir("other-condition");
    let server = StudyServer::start(config(""), &dir).unwrap();
    server.enrol(Population::NoLimitation).unwrap();
    drop(server);
    wait_for_lock_release(&dir);
    // The participant is at the query condition c01 (baselines come last).
    let log = dir.join("participants/p001.jsonl");
    let mut text = std::fs::read_to_string(&log).unwrap();
    text.push_str("{\"seq\": 1, \"unix_ms\": 1, \"event\": \"condition_started\", \"condition\": \"baseline_hard\"}\n");
    std::fs::write(&log, text).unwrap();
    let e = StudyServer::start(config(""), &dir)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("is about condition `baseline_hard`, but the participant is at condition `c01`"),
        "{e}"
    );
    assert!(!e.contains("Some("), "no Rust Debug output: {e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The researcher's link is kept in the data folder (the owner's only) and
/// works after a restart; an enrolment that names its participant is not
/// made twice when the serve command runs again.
#[test]
fn links_and_named_enrolments_survive_a_restart() {
    use hil_study::server::{Enrolment, RESEARCHER_TOKEN_FILE};
    let dir = temp_dir("restart-links");
    let server = StudyServer::start(config(""), &dir).unwrap();
    let researcher = server.researcher_urls()[0].clone();
    let (done, first) = server
        .enrol_as("p001", Population::MobilityLimitation)
        .unwrap();
    assert_eq!(done, Enrolment::New);
    drop(server);
    wait_for_lock_release(&dir);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        for secret in [RESEARCHER_TOKEN_FILE, "participants/p001.jsonl"] {
            let meta = std::fs::metadata(dir.join(secret)).unwrap();
            assert_eq!(meta.permissions().mode() & 0o777, 0o600, "{secret}");
        }
    }

    let server = StudyServer::start(config(""), &dir).unwrap();
    let addr = server.addr();
    // The old link (same token, and the last run's port unless something
    // else took it meanwhile) still opens the progress page.
    let old = token_of(&researcher);
    match server.moved_from() {
        None => assert_eq!(server.researcher_urls()[0], researcher),
        Some(p) => assert_eq!(researcher, format!("http://127.0.0.1:{p}/{old}/")),
    }
    assert_eq!(token_of(&server.researcher_urls()[0]), old);
    let (s, body) = get(addr, &format!("/{old}/api/progress"));
    assert_eq!(s, 200, "{body}");
    // Enrolling p001 again with the same population changes nothing.
    let (done, again) = server
        .enrol_as("p001", Population::MobilityLimitation)
        .unwrap();
    assert_eq!(done, Enrolment::Already);
    assert_eq!(token_of(&again[0]), token_of(&first[0]));
    let progress: Value =
        serde_json::from_str(&get(addr, &format!("/{old}/api/progress")).1).unwrap();
    assert_eq!(
        progress["participants"].as_array().unwrap().len(),
        1,
        "{progress}"
    );
    // With another population, it is refused; a name-like id too.
    let e = server
        .enrol_as("p001", Population::NoLimitation)
        .unwrap_err();
    assert!(matches!(e, HilError::InvalidParameter { .. }), "{e:?}");
    let e = server
        .enrol_as("Jane Doe", Population::NoLimitation)
        .unwrap_err();
    assert!(matches!(e, HilError::InvalidParameter { .. }), "{e:?}");
    // The researcher page's button takes the next free id.
    let (id, _) = server.enrol(Population::NoLimitation).unwrap();
    assert_eq!(id, "p002");
    let (done, _) = server.enrol_as("p004", Population::NoLimitation).unwrap();
    assert_eq!(done, Enrolment::New);
    assert_eq!(server.enrol(Population::NoLimitation).unwrap().0, "p003");
    assert_eq!(server.enrol(Population::NoLimitation).unwrap().0, "p005");
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Over HTTPS (asked for on loopback here; `--lan` always serves it): the
/// pages answer a client that pins the printed fingerprint, answers come
/// only from the https origin, plain HTTP gets no page, and a restart
/// keeps the self-signed certificate. Only loopback is used.
#[test]
#[cfg(feature = "https")]
fn https_serves_the_pages_with_a_kept_certificate() {
    use hil_http::testing::client::{get_https, post_https, raw};
    let dir = temp_dir("https");
    let cfg = config("[server]\nhttps = true\n");
    let server = StudyServer::start(cfg.clone(), &dir).unwrap();
    let addr = server.addr();
    assert!(addr.ip().is_loopback());
    let fingerprint = server.tls().expect("served over HTTPS").fingerprint();
    let (_, urls) = server.enrol(Population::NoLimitation).unwrap();
    assert!(urls[0].starts_with("https://127.0.0.1:"), "{urls:?}");
    let token = token_of(&urls[0]);
    let (s, page) = get_https(addr, &fingerprint, &format!("/{token}/"));
    assert_eq!(s, 200);
    assert!(page.contains("<html"), "{page}");
    let start = json!({"condition": "c01"}).to_string();
    let json = "Content-Type: application/json\r\n";
    let (s, _) = post_https(
        addr,
        &fingerprint,
        &format!("/{token}/api/start"),
        &format!("Origin: http://{addr}\r\n{json}"),
        &start,
    );
    assert_eq!(s, 403, "the http origin is another origin");
    let (s, body) = post_https(
        addr,
        &fingerprint,
        &format!("/{token}/api/start"),
        &format!("Origin: https://{addr}\r\n{json}"),
        &start,
    );
    assert_eq!(s, 200, "{body}");
    // Plain HTTP to the HTTPS port gets no page.
    let plain = std::panic::catch_unwind(|| {
        raw(
            addr,
            format!("GET /{token}/ HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes(),
        )
    });
    assert!(!matches!(plain, Ok((200, _))), "{plain:?}");
    drop(server);
    wait_for_lock_release(&dir);
    let server = StudyServer::start(cfg, &dir).unwrap();
    assert_eq!(server.tls().unwrap().fingerprint(), fingerprint);
    let (s, _) = get_https(server.addr(), &fingerprint, &format!("/{token}/api/state"));
    assert_eq!(s, 200);
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Beyond loopback the study is always served over HTTPS; on loopback
/// only when asked.
#[test]
fn plain_http_stays_on_loopback() {
    let mut s = hil_study::ServerConfig::default();
    assert!(!s.uses_https());
    for bind in ["0.0.0.0", "::", "192.168.1.20"] {
        s.bind = bind.parse().unwrap();
        assert!(s.uses_https(), "{bind}");
    }
    let e = StudyConfig::parse("[server]\ntls_cert = \"c.pem\"\n", "s.toml".as_ref()).unwrap_err();
    let HilError::Config(c) = &e else {
        panic!("{e:?}")
    };
    assert_eq!(c.field.as_deref(), Some("server.tls_cert"), "{e}");
}
