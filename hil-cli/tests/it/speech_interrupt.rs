//! Ctrl-C in a spoken session (`hil run`, `[channel] type = "speech"`):
//! the turn being heard finishes and is kept, then the session stops
//! before listening again, with the resume hint. The microphone and the
//! speaker are stand-ins on PATH: `arecord` streams silence in real time,
//! `aplay` plays nothing.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{send_signal, wait_at_most};

fn scratch() -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-cli-speech-stop-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("bin")).unwrap();
    d
}

fn script(path: &Path, body: &str) {
    std::fs::write(path, format!("#!/bin/sh\n{body}\n")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Starts the built `hil` binary with `args`, its stdout discarded and its
/// stderr piped; `path_first` goes before PATH (stand-in programs).
fn spawn_hil(args: &[&OsStr], path_first: Option<&Path>) -> Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_hil"));
    if let Some(dir) = path_first {
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut dirs = vec![dir.to_path_buf()];
        dirs.extend(std::env::split_paths(&path));
        cmd.env("PATH", std::env::join_paths(dirs).expect("a joinable PATH"));
    }
    cmd.args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the hil binary starts")
}

#[test]
fn ctrl_c_stops_a_spoken_session_between_utterances() {
    let dir = scratch();
    // The probe (`-s N`) records N samples and ends; a turn streams 0.1 s
    // of silence every 0.1 s, like a quiet room.
    script(
        &dir.join("bin/arecord"),
        r#"case " $* " in *" -s "*) exit 0;; esac
python3 -c '
import sys, time
while True:
    sys.stdout.buffer.write(bytes(3200)); sys.stdout.buffer.flush(); time.sleep(0.1)
'"#,
    );
    script(&dir.join("bin/aplay"), "exit 0");
    let config = dir.join("session.toml");
    std::fs::write(
        &config,
        crate::demo::DemoSession {
            episodes: 1,
            policy: "query_probability = 1.0",
            channel: "type = \"speech\"\ntimeout_s = 1.0\nmax_reasks = 10\naudio_dir = \"audio\"",
            ..crate::demo::DemoSession::default()
        }
        .toml(),
    )
    .unwrap();
    let log = dir.join("s.jsonl");
    let args = [
        OsStr::new("run"),
        "--config".as_ref(),
        config.as_ref(),
        "--log".as_ref(),
        log.as_ref(),
    ];
    let mut child = spawn_hil(&args, Some(&dir.join("bin")));
    // Once the first turn (1 s of silence) is kept, the channel says
    // "please say that again" and listens again: the signal lands in that
    // prompt or in the second turn.
    let first = dir.join("audio/step-1-turn-0.json");
    let started = Instant::now();
    while !first.exists() {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no turn was heard"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    send_signal(&child, "-INT");
    let status = wait_at_most(&mut child, Duration::from_secs(20));
    if status.is_none() {
        let _ = child.kill();
    }
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let status = status.expect("hil run did not stop");
    // Not the immediate exit (130) of a session without speech: the
    // channel stopped the session at its next check between utterances
    // (a turn under way is finished and kept first), so no turn starts
    // after the one the signal may have landed in.
    assert_ne!(status.code(), Some(130), "{stderr}");
    assert!(!status.success(), "{stderr}");
    assert!(stderr.contains("hil run --resume"), "{stderr}");
    assert!(stderr.contains("stopped (Ctrl-C)"), "{stderr}");
    assert!(!dir.join("audio/step-1-turn-2.json").exists(), "{stderr}");
    assert!(log.exists(), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
