//! `hil` writing into pipes whose reader has gone: a closed stdout ends
//! the command quietly with the status a shell gives a program SIGPIPE
//! ended (128 + 13), not a panic (101); a closed stderr never keeps `hil
//! run` from stopping on SIGTERM, nor stops a run that prints progress.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{send_signal, wait_at_most};
use crate::demo::{DemoSession, scratch_dir};

/// 128 + SIGPIPE: what `yes | head -1` reports for `yes`.
const CLOSED_STDOUT: i32 = 141;

fn hil() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hil"))
}

/// Runs `hil args` with a stdout pipe whose read end is closed as soon as
/// the child is started (before it has loaded anything it could print).
fn with_closed_stdout(args: &[&str]) -> Output {
    let mut child = hil()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    child.wait_with_output().unwrap()
}

fn assert_quiet_closed_stdout(out: &Output, what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(CLOSED_STDOUT), "{what}: {err}");
    assert!(err.is_empty(), "{what} printed: {err}");
}

#[test]
fn every_printing_command_ends_quietly_on_a_closed_stdout() {
    let dir = scratch_dir("closed-pipes", "stdout");
    let data = dir.join("foods");
    let made = hil()
        .args(["data", "generate", "--dim", "224", "--out"])
        .arg(&data)
        .output()
        .unwrap();
    assert!(made.status.success(), "{made:?}");
    let study =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-workload/data/synthetic_study.csv");
    let config = dir.join("exp.toml");
    std::fs::write(&config, run_config(2)).unwrap();

    let cases: [(&str, Vec<&str>); 4] = [
        ("data check", vec!["data", "check", data.to_str().unwrap()]),
        (
            "workload summary",
            vec!["workload", "summary", "--data", study.to_str().unwrap()],
        ),
        (
            "workload rollout",
            vec![
                "workload",
                "rollout",
                "--model",
                "bundled:f1_sim",
                "--schedule",
                "3,8",
                "--steps",
                "20000",
            ],
        ),
        (
            "run --json",
            vec!["run", "--json", "--config", config.to_str().unwrap()],
        ),
    ];
    for (what, args) in cases {
        assert_quiet_closed_stdout(&with_closed_stdout(&args), what);
    }
}

/// A demo session of `episodes` episodes that never waits for anyone.
fn run_config(episodes: usize) -> String {
    DemoSession {
        episodes,
        repeat: 4,
        ..DemoSession::default()
    }
    .toml()
}

/// Starts `hil run` on `episodes` episodes, logging to `log`, with a stderr
/// pipe whose reader has gone.
fn run_with_closed_stderr(dir: &Path, episodes: usize, quiet: bool) -> (Child, PathBuf) {
    let config = dir.join("exp.toml");
    std::fs::write(&config, run_config(episodes)).unwrap();
    let log = dir.join("log.jsonl");
    let mut cmd = hil();
    cmd.arg("run")
        .arg("--config")
        .arg(&config)
        .arg("--log")
        .arg(&log);
    if quiet {
        cmd.arg("--quiet");
    }
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    (child, log)
}

#[test]
fn sigterm_stops_a_run_whose_stderr_reader_has_gone() {
    let dir = scratch_dir("closed-pipes", "sigterm");
    // Far more episodes than can run before the deadline below.
    let (mut child, log) = run_with_closed_stderr(&dir, 100_000, true);
    // The interrupt handler is installed before the log is created.
    let started = Instant::now();
    while std::fs::metadata(&log).map_or(0, |m| m.len()) == 0 {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "the run never started"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    send_signal(&child, "-TERM");
    let status = wait_at_most(&mut child, Duration::from_secs(20));
    if status.is_none() {
        let _ = child.kill();
        let _ = child.wait();
    }
    assert_eq!(status.and_then(|s| s.code()), Some(130), "{status:?}");
}

#[test]
fn a_closed_stderr_does_not_stop_a_run_that_prints_progress() {
    let dir = scratch_dir("closed-pipes", "progress");
    let (mut child, log) = run_with_closed_stderr(&dir, 3, false);
    let status = wait_at_most(&mut child, Duration::from_secs(120));
    if status.is_none() {
        let _ = child.kill();
    }
    assert!(status.is_some_and(|s| s.success()), "{status:?}");
    let log = std::fs::read_to_string(log).unwrap();
    assert_eq!(log.matches(r#""record":"episode_end""#).count(), 3);
}
