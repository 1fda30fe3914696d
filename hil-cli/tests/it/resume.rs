//! Kill-and-resume on a real `hil run` child process: killed with SIGKILL at
//! arbitrary points and resumed with `--resume`, the session's log and
//! summary equal an uninterrupted run's.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::demo::{DemoSession, lines_without_markers, scratch_dir};

fn config_text() -> String {
    DemoSession {
        seed: 11,
        episodes: 3,
        n_att: Some(4),
        foods: r#""banana", "carrot", "grape", "cantaloupe", "apple""#,
        repeat: 4,
        policy: r#"query_probability = 0.5
epsilon = 0.2
kinds = [{ response = "mcq" }, { response = "bounding_box", difficulty = "hard" }, { response = "open_ended" }]"#,
        channel: r#"type = "simulated_expert"
error_rate = 0.2
decline_rate = 0.15
response_time = { median_s = 4.0, sigma = 0.5 }"#,
    }
    .toml()
}

fn hil() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hil"))
}

fn tmp_dir(name: &str) -> PathBuf {
    scratch_dir("cli", name)
}

fn line_count(path: &Path) -> usize {
    std::fs::read(path)
        .map(|b| b.iter().filter(|c| **c == b'\n').count())
        .unwrap_or(0)
}

#[test]
fn killed_sessions_resume_to_the_uninterrupted_result() {
    let dir = tmp_dir("resume");
    let config = dir.join("exp.toml");
    std::fs::write(&config, config_text()).unwrap();

    let reference = dir.join("reference.jsonl");
    let out = hil()
        .args(["run", "--json", "--config"])
        .arg(&config)
        .arg("--log")
        .arg(&reference)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reference_summary = String::from_utf8(out.stdout).unwrap();
    let reference_lines = lines_without_markers(&reference);
    let total = reference_lines.len();
    assert!(total > 100, "a session long enough to kill: {total} lines");

    // Kill points spread over the session (in log lines written so far).
    let log = dir.join("killed.jsonl");
    let mut kills = 0;
    let targets = [3, total / 5, total / 2, total * 4 / 5, total - 2];
    for (i, target) in targets.into_iter().enumerate() {
        let mut cmd = hil();
        cmd.arg("run").arg("--quiet");
        if i == 0 {
            cmd.arg("--config").arg(&config).arg("--log").arg(&log);
        } else {
            cmd.arg("--resume").arg(&log);
        }
        let mut child = cmd
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            if line_count(&log) >= target {
                child.kill().unwrap(); // SIGKILL
                let status = child.wait().unwrap();
                if !status.success() {
                    kills += 1;
                }
                break;
            }
            if let Some(status) = child.try_wait().unwrap() {
                assert!(status.success(), "run {i} failed");
                break;
            }
            assert!(Instant::now() < deadline, "run {i} hung");
            std::thread::sleep(Duration::from_micros(200));
        }
    }
    assert!(kills >= 3, "only {kills} runs were killed mid-session");

    let out = hil()
        .args(["run", "--json", "--resume"])
        .arg(&log)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(String::from_utf8(out.stdout).unwrap(), reference_summary);
    let resumed = lines_without_markers(&log);
    assert_eq!(resumed.len(), reference_lines.len());
    for (i, (a, b)) in resumed.iter().zip(&reference_lines).enumerate() {
        assert_eq!(a, b, "line {} differs", i + 1);
    }
    let markers = std::fs::read_to_string(&log)
        .unwrap()
        .matches(r#""record":"resumed""#)
        .count();
    assert!(markers >= 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resume_and_log_errors_are_clear() {
    let dir = tmp_dir("errors");
    let missing = dir.join("missing.jsonl");
    let out = hil()
        .arg("run")
        .arg("--resume")
        .arg(&missing)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("missing.jsonl"), "{err}");

    let config = dir.join("exp.toml");
    std::fs::write(&config, config_text()).unwrap();
    let log = dir.join("log.jsonl");
    std::fs::write(&log, "").unwrap();
    let out = hil()
        .arg("run")
        .arg("--config")
        .arg(&config)
        .arg("--log")
        .arg(&log)
        .output()
        .unwrap();
    assert!(
        !out.status.success(),
        "an existing log must not be overwritten"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("log.jsonl"));

    let out = hil()
        .arg("run")
        .arg("--config")
        .arg(&config)
        .arg("--resume")
        .arg(&log)
        .output()
        .unwrap();
    assert!(!out.status.success(), "--config and --resume conflict");
    std::fs::remove_dir_all(&dir).unwrap();
}
