//! Shared by the integration tests that run the `hil` binary.

use std::process::{Child, Command, ExitStatus, Output};
use std::time::{Duration, Instant};

/// Runs the built `hil` binary with `args` and returns its output.
pub fn hil(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hil"))
        .args(args)
        .output()
        .expect("the hil binary runs")
}

/// Runs `hil ARGS --write-doc PAGE` in a scratch folder named after
/// `name`, asserts it succeeded and that the page holds the printed report
/// verbatim and names the command (`command` is its start); returns the
/// report.
pub fn report_kept_as_page(name: &str, args: &[&str], command: &str) -> String {
    let dir = std::env::temp_dir().join(format!("hil-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let page = dir.join("results").join("page.md");
    let mut full = args.to_vec();
    full.extend_from_slice(&["--write-doc", page.to_str().unwrap()]);
    let out = hil(&full);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = String::from_utf8(out.stdout).unwrap();
    let md = std::fs::read_to_string(&page).unwrap();
    assert!(md.contains(&format!("```text\n{report}```")), "{md}");
    assert!(md.contains(command), "{md}");
    let _ = std::fs::remove_dir_all(&dir);
    report
}

/// The child's exit status, if it ends within `limit`.
pub fn wait_at_most(child: &mut Child, limit: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + limit;
    while Instant::now() < deadline {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
}

/// Sends `signal` (e.g. `-INT`, `-TERM`) to `child` with kill(1).
pub fn send_signal(child: &Child, signal: &str) {
    let sent = Command::new("kill")
        .arg(signal)
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(sent.success(), "kill {signal} failed");
}
