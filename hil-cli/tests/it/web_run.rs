//! `hil run` with a web-channel config: the URL is printed, a person
//! answers over HTTP, an unanswered query times out, and the log records
//! both (the timed-out step executes the policy's fallback).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const CONFIG: &str = r#"
seed = 5
episodes = 1

[session]
n_att = 1

[environment]
type = "demo_plate"
foods = ["banana", "carrot"]

[policy]
type = "demo_learner"
query_probability = 1.0

[workload]
type = "demo_counting"
increment = 0.1
window = 10

[channel]
type = "web"
timeout_s = 1.5
"#;

/// One HTTP request to the page's server; returns (status, body).
fn request(host: &str, method: &str, path: &str, body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(host).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    let status = out.split(' ').nth(1).unwrap().parse().unwrap();
    (status, out.split_once("\r\n\r\n").unwrap().1.to_string())
}

#[test]
fn web_run_prints_the_url_records_answers_and_timeouts() {
    let dir = std::env::temp_dir().join(format!("hil-web-run-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("web.toml");
    std::fs::write(&config, CONFIG).unwrap();
    let log = dir.join("log.jsonl");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hil"))
        .args(["run", "--quiet", "--config"])
        .arg(&config)
        .arg("--log")
        .arg(&log)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut url = String::new();
    let mut line = String::new();
    while stderr.read_line(&mut line).unwrap() > 0 {
        if let Some(u) = line.trim().strip_prefix("http://") {
            url = u.to_string();
            break;
        }
        line.clear();
    }
    assert!(!url.is_empty(), "no URL printed");
    let (host, rest) = url.split_once('/').unwrap();
    let token = rest.trim_end_matches('/');
    assert!(host.starts_with("127.0.0.1:"), "{host}");

    // Answer the first query (banana) with TA0.
    let deadline = Instant::now() + Duration::from_secs(20);
    let id = loop {
        let (s, body) = request(host, "GET", &format!("/{token}/api/query"), "");
        assert_eq!(s, 200);
        let v: serde_json::Value = serde_json::from_str(&body).unwrap();
        if v["state"] == "query" {
            assert_eq!(v["item"]["label"], "banana");
            assert_eq!(
                v["kind_text"],
                "multiple choice · easy question · no distraction"
            );
            break v["id"].as_u64().unwrap();
        }
        assert!(Instant::now() < deadline, "no query");
        std::thread::sleep(Duration::from_millis(20));
    };
    let (s, _) = request(
        host,
        "POST",
        &format!("/{token}/api/answer"),
        &format!(r#"{{"id":{id},"answer":{{"type":"action","arm":4}}}}"#),
    );
    assert_eq!(s, 200);
    // Leave the second (carrot) unanswered: it times out.
    let status = child.wait().unwrap();
    let mut rest_err = String::new();
    stderr.read_to_string(&mut rest_err).unwrap();
    assert!(status.success(), "{rest_err}");

    let steps: Vec<serde_json::Value> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["record"] == "step")
        .map(|v| v["step"].clone())
        .collect();
    assert_eq!(steps.len(), 2);
    assert_eq!(steps[0]["response"]["answer"]["type"], "action");
    assert_eq!(steps[0]["arm"], 4);
    assert_eq!(steps[1]["item_label"], "carrot");
    assert_eq!(steps[1]["response"]["answer"]["type"], "timed_out");
    assert_eq!(steps[1]["response"]["expert_arm"], serde_json::Value::Null);
    assert_eq!(steps[1]["response"]["response_time_s"], 1.5);
    assert_eq!(steps[1]["arm"], steps[1]["decision"]["fallback"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
