//! `hil record keygen`, `hil record verify` and `hil run --record-key`: a
//! keyed log verifies and resumes with its key only, an edited one is
//! refused with the file and line, and a key file others may read is
//! refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::demo::{DemoSession, lines_without_markers, scratch_dir};

fn hil(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hil"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

fn refused(out: &Output) -> String {
    assert!(!out.status.success(), "expected a refusal");
    String::from_utf8(out.stderr.clone()).unwrap()
}

fn os(p: &Path) -> &std::ffi::OsStr {
    p.as_os_str()
}

/// `hil run [FLAG] --config CONFIG --log LOG --record-key KEY`.
fn keyed_run(flag: &str, config: &Path, log: &Path, key: &Path) -> Output {
    let mut args: Vec<&std::ffi::OsStr> = vec!["run".as_ref()];
    if !flag.is_empty() {
        args.push(flag.as_ref());
    }
    args.extend([
        "--config".as_ref(),
        os(config),
        "--log".as_ref(),
        os(log),
        "--record-key".as_ref(),
        os(key),
    ]);
    hil(&args)
}

fn setup(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = scratch_dir("record-cmd", name);
    let config = dir.join("exp.toml");
    std::fs::write(&config, DemoSession::default().toml()).unwrap();
    let key = dir.join("record.key");
    ok(&hil(&["record".as_ref(), "keygen".as_ref(), os(&key)]));
    (dir, config, key)
}

#[test]
fn a_keyed_run_verifies_and_resumes_with_its_key_only() {
    let (dir, config, key) = setup("keyed");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&key).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
    }
    let log = dir.join("log.jsonl");
    let summary = ok(&keyed_run("--json", &config, &log, &key));
    let verified = ok(&hil(&[
        "record".as_ref(),
        "verify".as_ref(),
        os(&log),
        "--key".as_ref(),
        os(&key),
    ]));
    assert!(verified.contains("keyed"), "{verified}");

    // Without the key: refused, naming the log and its header line.
    let e = refused(&hil(&["record".as_ref(), "verify".as_ref(), os(&log)]));
    assert!(e.contains(&format!("{}:1:", log.display())), "{e}");
    let e = refused(&hil(&["run".as_ref(), "--resume".as_ref(), os(&log)]));
    assert!(e.contains("record_key"), "{e}");

    // Cut and resumed with the key: the same log and summary.
    let whole = lines_without_markers(&log);
    let cut = dir.join("cut.jsonl");
    std::fs::write(&cut, whole[..whole.len() / 2].join("\n") + "\n").unwrap();
    let resumed = ok(&hil(&[
        "run".as_ref(),
        "--json".as_ref(),
        "--resume".as_ref(),
        os(&cut),
        "--record-key".as_ref(),
        os(&key),
    ]));
    assert_eq!(resumed, summary);
    assert_eq!(lines_without_markers(&cut), whole);

    // A changed byte in a line: refused with that line.
    let mut lines = whole.clone();
    lines[3] = lines[3].replacen("\"episode\":0", "\"episode\":1", 1);
    assert_ne!(lines[3], whole[3]);
    std::fs::write(&cut, lines.join("\n") + "\n").unwrap();
    let e = refused(&hil(&[
        "record".as_ref(),
        "verify".as_ref(),
        os(&cut),
        "--key".as_ref(),
        os(&key),
    ]));
    assert!(e.contains(&format!("{}:4:", cut.display())), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn a_key_file_others_may_read_is_refused() {
    use std::os::unix::fs::PermissionsExt;
    let (dir, config, key) = setup("perm");
    std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o640)).unwrap();
    let log = dir.join("log.jsonl");
    let e = refused(&keyed_run("", &config, &log, &key));
    assert!(e.contains(&key.display().to_string()), "{e}");
    assert!(e.contains("chmod 600"), "{e}");
    // Nothing was recorded under a key that is not private.
    assert!(!log.exists());
    // A directory given as the key is named as one, not asked to be chmod'ed.
    let e = refused(&keyed_run("", &config, &log, &dir));
    assert!(e.contains("a directory"), "{e}");
    assert!(!e.contains("chmod"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unkeyed_log_verifies_without_a_key() {
    let (dir, config, key) = setup("unkeyed");
    let log = dir.join("log.jsonl");
    ok(&hil(&[
        "run".as_ref(),
        "--quiet".as_ref(),
        "--config".as_ref(),
        os(&config),
        "--log".as_ref(),
        os(&log),
    ]));
    let out = ok(&hil(&["record".as_ref(), "verify".as_ref(), os(&log)]));
    assert!(out.contains("unkeyed"), "{out}");
    // A key for an unkeyed log is refused: a keyed log stripped of its
    // keying would look like this.
    let e = refused(&hil(&[
        "record".as_ref(),
        "verify".as_ref(),
        os(&log),
        "--key".as_ref(),
        os(&key),
    ]));
    assert!(e.contains("not keyed"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
