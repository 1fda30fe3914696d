//! `hil study serve` killed (SIGKILL) in the middle of a condition, with a
//! query answered and its survey not yet submitted, then served again on
//! the same data folder: the participant continues where they were,
//! nothing saved is lost, a survey sent again is not saved twice, and the
//! export has exactly one row per survey. Then the README's loop: export,
//! `hil workload summary`, `hil workload fit`, a `hil run` with the model.

use crate::common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

const CONFIG: &str = r#"
[design]
difficulties = ["easy"]
distractions = ["none"]
intervals_min = [1]
baselines = ["easy"]
time_scale = 60
"#;

/// A running `hil study serve`: the process and the URLs it printed.
struct Serve {
    child: Child,
    researcher: String,
    participant: Option<String>,
}

fn serve(config: &Path, data: &Path, enrol: bool) -> Serve {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_hil"));
    cmd.args(["study", "serve", "--config"])
        .arg(config)
        .arg("--data")
        .arg(data);
    if enrol {
        cmd.args(["--enrol", "p001=mobility_limitation"]);
    }
    let mut child = cmd.stdout(Stdio::piped()).spawn().unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let (mut researcher, mut participant) = (None, None);
    let mut next_is = "";
    loop {
        let mut line = String::new();
        assert!(out.read_line(&mut line).unwrap() > 0, "serve exited early");
        let line = line.trim().to_string();
        if line.starts_with("Serving") {
            break;
        }
        match next_is {
            "researcher" => researcher = Some(line.clone()),
            "participant" => participant = Some(line.clone()),
            _ => {}
        }
        next_is = if line.starts_with("Researcher") {
            "researcher"
        } else if line.starts_with("Participant") {
            "participant"
        } else {
            ""
        };
    }
    // Keep reading so the child never blocks on a full pipe.
    std::thread::spawn(move || {
        let _ = std::io::copy(&mut out, &mut std::io::sink());
    });
    Serve {
        child,
        researcher: researcher.expect("a researcher URL"),
        participant,
    }
}

/// One HTTP request to `url` (+ `path`); returns the status and JSON body.
fn request(url: &str, path: &str, body: Option<&Value>) -> (u16, Value) {
    let rest = url.trim_start_matches("http://");
    let (host, base) = rest.split_once('/').unwrap();
    let mut s = TcpStream::connect(host).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    let target = format!("/{base}{path}");
    let req = match body {
        Some(b) => {
            let b = b.to_string();
            format!(
                "POST {target} HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{b}",
                b.len()
            )
        }
        None => format!("GET {target} HTTP/1.1\r\nHost: {host}\r\n\r\n"),
    };
    s.write_all(req.as_bytes()).unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    let status = text.split(' ').nth(1).unwrap().parse().unwrap();
    let body = text.split_once("\r\n\r\n").unwrap().1;
    (status, serde_json::from_str(body).unwrap_or(Value::Null))
}

/// Polls the state until `pred` holds.
fn until(url: &str, what: &str, pred: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, v) = request(url, "api/state", None);
        assert_eq!(status, 200, "{v}");
        if pred(&v) {
            return v;
        }
        assert!(Instant::now() < deadline, "waiting for {what}: {v}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn tlx(v: u8) -> Value {
    json!({"mental": v, "temporal": 2, "performance": 4, "effort": v, "frustration": 1})
}

/// Answers the open query with an answer of the right kind.
fn answer(url: &str, v: &Value) {
    let q = &v["query"];
    let answer = match q["kind"].as_str().unwrap() {
        "mcq" => json!({"type": "label", "label": q["options"][0]}),
        "bounding_box" => {
            json!({"type": "bounding_box", "bbox": {"x0": 0.1, "y0": 0.1, "x1": 0.4, "y1": 0.5}})
        }
        _ => json!({"type": "text", "text": "too soft"}),
    };
    let (s, r) = request(
        url,
        "api/answer",
        Some(&json!({"condition": v["condition"]["id"], "query": q["number"], "answer": answer})),
    );
    assert_eq!((s, &r["already_saved"]), (200, &json!(false)), "{r}");
}

fn survey(url: &str, condition: &str, query: Value, level: u8) -> Value {
    let (s, r) = request(
        url,
        "api/survey",
        Some(&json!({"condition": condition, "query": query, "tlx": tlx(level)})),
    );
    assert_eq!(s, 200, "{r}");
    r
}

fn events(data: &Path) -> Vec<Value> {
    std::fs::read_to_string(data.join("participants/p001.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn killed_mid_condition_the_study_resumes_without_loss_or_duplicates() {
    let dir = std::env::temp_dir().join(format!("hil-study-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("study.toml");
    std::fs::write(&config, CONFIG).unwrap();
    let data = dir.join("data");

    let mut a = serve(&config, &data, true);
    let p = a.participant.clone().expect("a participant link");
    // Baseline: start, wait for its end survey, submit.
    let v = until(&p, "intro", |v| v["phase"] == "intro");
    assert_eq!(v["condition"]["id"], "baseline_easy");
    assert_eq!(
        request(
            &p,
            "api/start",
            Some(&json!({"condition": "baseline_easy"}))
        )
        .0,
        200
    );
    until(&p, "baseline survey", |v| v["phase"] == "survey");
    survey(&p, "baseline_easy", Value::Null, 2);
    // c01: two queries with their surveys, a third answered, then kill.
    until(&p, "c01 intro", |v| v["phase"] == "intro");
    assert_eq!(
        request(&p, "api/start", Some(&json!({"condition": "c01"}))).0,
        200
    );
    for k in 0..3 {
        let v = until(&p, "a query", |v| v["query"]["number"] == json!(k));
        answer(&p, &v);
        if k < 2 {
            until(&p, "its survey", |v| v["phase"] == "survey");
            survey(&p, "c01", json!(k), 3);
        }
    }
    a.child.kill().unwrap(); // SIGKILL: no chance to clean up
    a.child.wait().unwrap();
    let before = events(&data);
    assert_eq!(
        before
            .iter()
            .filter(|e| e["event"] == "survey_submitted")
            .count(),
        3
    );

    // Served again with the same command: nobody new is enrolled, and the
    // researcher's and the participant's links hold the tokens printed
    // before (the port is a free one, as the config asks).
    let mut b = serve(&config, &data, true);
    let token = |url: &str| {
        url.trim_end_matches('/')
            .rsplit('/')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(token(&b.researcher), token(&a.researcher));
    assert_eq!(b.participant.as_deref().map(token), Some(token(&p)));
    let (s, progress) = request(&b.researcher, "api/progress", None);
    assert_eq!(s, 200);
    let row = &progress["participants"][0];
    assert_eq!(
        (row["participant"].as_str(), row["surveys"].as_u64()),
        (Some("p001"), Some(3))
    );
    let host = b
        .researcher
        .trim_start_matches("http://")
        .split('/')
        .next()
        .unwrap()
        .to_string();
    let p = format!("http://{host}{}", row["link"].as_str().unwrap());
    // Where they were: the survey after query 2 is due.
    let v = until(&p, "the pending survey", |v| v["phase"] == "survey");
    assert_eq!(v["survey"]["query"], json!(2));
    // A survey sent again (its response lost in the crash) is not saved twice.
    let again = survey(&p, "c01", json!(1), 3);
    assert_eq!(again["already_saved"], json!(true));
    survey(&p, "c01", json!(2), 4);
    for k in 3..5 {
        let v = until(&p, "a query", |v| v["query"]["number"] == json!(k));
        answer(&p, &v);
        until(&p, "its survey", |v| {
            v["phase"] == "survey" && v["survey"]["query"] == json!(k)
        });
        survey(&p, "c01", json!(k), 3);
    }
    until(&p, "the end survey", |v| {
        v["phase"] == "survey" && v["survey"]["query"].is_null()
    });
    survey(&p, "c01", Value::Null, 3);
    until(&p, "done", |v| v["phase"] == "done");
    b.child.kill().unwrap();
    b.child.wait().unwrap();

    // Nothing lost: the log before the kill is a prefix of the log now.
    let after = events(&data);
    assert_eq!(after[..before.len()], before[..]);
    let mut keys = std::collections::BTreeSet::new();
    for e in after.iter().filter(|e| e["event"] == "survey_submitted") {
        assert!(
            keys.insert((e["condition"].to_string(), e["query"].to_string())),
            "duplicate survey {e}"
        );
    }
    assert_eq!(keys.len(), 7); // baseline end, 5 query surveys, c01 end

    // The README's loop: export, summary, fit, run with the model.
    let csv = dir.join("study.csv");
    let out = common::hil(&[
        "study",
        "export",
        "--data",
        data.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Every survey is exported, as many as status counts: c01's
    // end-of-condition survey goes to the second CSV.
    let said = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(said.starts_with("wrote 7 surveys: 6 to "), "{said}");
    let end = std::fs::read_to_string(dir.join("study.end_of_condition.csv")).unwrap();
    let rows: Vec<&str> = end.lines().skip(1).collect();
    assert_eq!(rows.len(), 1, "{end}");
    assert!(
        rows[0].starts_with("p001,mobility_limitation,c01,"),
        "{end}"
    );
    let out = common::hil(&["workload", "summary", "--data", csv.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pairs = |id: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(id))
            .unwrap_or_else(|| panic!("no {id} in {text}"))
            .to_string()
    };
    assert!(pairs("D2").starts_with("D2: 5 pairs"), "{text}");
    assert!(pairs("D12").starts_with("D12: 5 pairs"), "{text}");
    assert!(
        !text.contains("D1:"),
        "no participant without a limitation: {text}"
    );
    let status = common::hil(&["study", "status", "--data", data.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&status.stdout).contains(
        "p001 mobility_limitation: 2/2 conditions, 7 surveys (6 in the study CSV, \
                 1 at the end of a query condition)"
    ));
    let model = dir.join("m.json");
    let out = common::hil(&[
        "workload",
        "fit",
        "--data",
        csv.to_str().unwrap(),
        "--population",
        "d12",
        "--model",
        "granger_rn",
        "--history",
        "1",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    hil_workload::load_model_json(&model).unwrap();
    // LinUCB-QG with the fitted model: the quickstart experiment with the
    // README's `[workload]` table.
    let quickstart = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/configs/quickstart.toml"
    ))
    .unwrap();
    let (head, tail) = quickstart.split_once("[workload]").unwrap();
    let tail = &tail[tail.find("\n[").unwrap()..];
    let run = format!(
        "{}[workload]\ntype = \"model_file\"\npath = \"m.json\"\n{tail}",
        head.replace("episodes = 3", "episodes = 1")
    );
    assert!(run.contains("type = \"linucb_qg\""));
    std::fs::write(dir.join("run.toml"), run).unwrap();
    let out = common::hil(&[
        "run",
        "--config",
        dir.join("run.toml").to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
