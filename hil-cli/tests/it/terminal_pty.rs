//! The terminal channel through a real pseudo-terminal: `hil run` with a
//! terminal-channel config, answered by a person simulated at the other end
//! of a pty (python3's `pty` module), interrupted with Ctrl-C, resumed, and
//! ended with Ctrl-D.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A session that asks at every decision, at the terminal.
fn config_text() -> String {
    crate::demo::DemoSession {
        seed: 3,
        episodes: 1,
        n_att: Some(2),
        policy: r#"query_probability = 1.0
kinds = [{ response = "mcq" }, { response = "bounding_box", difficulty = "hard" }, { response = "open_ended", distraction = "easy" }]"#,
        channel: r#"type = "terminal""#,
        ..crate::demo::DemoSession::default()
    }
    .toml()
}

#[derive(Debug)]
struct Outcome {
    answered: u64,
    exit_code: Option<i64>,
    #[allow(dead_code)] // shown in failure messages
    signal: Option<i64>,
    output: String,
}

fn drive(mode: &str, args: &[&std::ffi::OsStr]) -> Outcome {
    let driver = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/pty_driver.py");
    let out = Command::new("python3")
        .arg(driver)
        .arg(mode)
        .arg(env!("CARGO_BIN_EXE_hil"))
        .args(args)
        .output()
        .expect("python3 is needed to drive a pseudo-terminal");
    assert!(
        out.status.success(),
        "driver failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    Outcome {
        answered: v["answered"].as_u64().unwrap(),
        exit_code: v["exit_code"].as_i64(),
        signal: v["signal"].as_i64(),
        output: v["output"].as_str().unwrap().to_string(),
    }
}

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-pty-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn logged_responses(log: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(log)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["record"] == "step" && !v["step"]["response"].is_null())
        .collect()
}

#[test]
#[ignore = "e2e: needs a PTY (python3 pty); bash scripts/test runs it"]
fn answered_interrupted_and_resumed_through_a_pty() {
    let dir = tmp_dir("interrupt");
    let config = dir.join("terminal.toml");
    std::fs::write(&config, config_text()).unwrap();
    let log = dir.join("log.jsonl");

    // Answer two queries, then Ctrl-C at the third prompt.
    let first = drive(
        "interrupt-after-2",
        &[
            "run".as_ref(),
            "--config".as_ref(),
            config.as_os_str(),
            "--log".as_ref(),
            log.as_os_str(),
        ],
    );
    assert_eq!(first.answered, 2, "{}", first.output);
    assert_eq!(
        first.exit_code,
        Some(130),
        "Ctrl-C ends the process: {first:?}"
    );
    assert!(
        first
            .output
            .contains("interrupted: every answered step is in"),
        "{}",
        first.output
    );
    assert!(
        first.output.contains("hil run --resume"),
        "{}",
        first.output
    );
    assert!(
        first
            .output
            .contains("Kind: multiple choice · easy question · no distraction")
    );
    assert!(
        first
            .output
            .contains("Kind: bounding box · hard question · no distraction")
    );
    assert_eq!(logged_responses(&log).len(), 2, "both answers are on disk");

    // Resume: the two answered queries are not asked again.
    let second = drive(
        "answer-all",
        &["run".as_ref(), "--resume".as_ref(), log.as_os_str()],
    );
    assert_eq!(second.exit_code, Some(0), "{}", second.output);
    assert!(second.output.contains("resuming"), "{}", second.output);
    assert!(second.output.contains("1 episode(s)"), "{}", second.output);
    let responses = logged_responses(&log);
    let asked_again = second.answered as usize;
    assert_eq!(
        responses.len(),
        2 + asked_again,
        "no answer lost or duplicated"
    );
    assert!(asked_again >= 1);
    let ts: Vec<u64> = responses
        .iter()
        .map(|v| v["step"]["t"].as_u64().unwrap())
        .collect();
    assert!(ts.windows(2).all(|w| w[0] < w[1]), "{ts:?}");
    // What was typed is what was recorded, with the kind that was shown.
    assert_eq!(
        responses[0]["step"]["response"]["answer"],
        serde_json::json!({"type": "action", "arm": 1})
    );
    assert_eq!(responses[0]["step"]["decision"]["kind"]["response"], "mcq");
    assert_eq!(
        responses[1]["step"]["response"]["answer"],
        serde_json::json!({"type": "bounding_box", "bbox": {"x0": 0.25, "y0": 0.3, "x1": 0.75, "y1": 0.8}})
    );
    assert_eq!(
        responses[2]["step"]["response"]["answer"],
        serde_json::json!({"type": "text", "text": "try TA0"})
    );
    assert_eq!(responses[2]["step"]["response"]["expert_arm"], 4);
    assert_eq!(
        responses[2]["step"]["decision"]["kind"]["distraction"],
        "easy"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[ignore = "e2e: needs a PTY (python3 pty); bash scripts/test runs it"]
fn end_of_input_stops_with_a_clear_error() {
    let dir = tmp_dir("eof");
    let config = dir.join("terminal.toml");
    std::fs::write(&config, config_text()).unwrap();
    let log = dir.join("log.jsonl");
    let out = drive(
        "eof-after-1",
        &[
            "run".as_ref(),
            "--config".as_ref(),
            config.as_os_str(),
            "--log".as_ref(),
            log.as_os_str(),
        ],
    );
    assert_eq!(out.exit_code, Some(1), "{out:?}");
    assert!(out.output.contains("input ended"), "{}", out.output);
    assert!(out.output.contains("--resume"), "{}", out.output);
    assert_eq!(logged_responses(&log).len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
