//! Keyed interaction logs (HMAC-SHA256, the key kept outside the log): a
//! keyed log that was edited and re-chained without its key is refused,
//! whether re-chained unkeyed or with another key; its key verifies and
//! resumes it to the uninterrupted result; an unkeyed log is written as
//! before, byte for byte.

use std::path::{Path, PathBuf};

use hil_core::HilError;
use hil_experiments::run::Run;
use hil_record::chain::{self, Chain};
use hil_record::{Header, RecordKey, RecordLog};

use crate::demo::{DemoSession, lines_without_markers, scratch_dir};

fn tmp_dir(name: &str) -> PathBuf {
    scratch_dir("record-keyed", name)
}

/// Writes the demo config into `dir` and returns its path.
fn config(dir: &Path) -> PathBuf {
    let path = dir.join("exp.toml");
    std::fs::write(&path, DemoSession::default().toml()).unwrap();
    path
}

/// A finished keyed run: the log's path, its key's path and the summary.
fn keyed_run(dir: &Path) -> (PathBuf, PathBuf, String) {
    let key = dir.join("record.key");
    RecordKey::generate(&key).unwrap();
    let log = dir.join("keyed.jsonl");
    let summary = Run::from_config_with_key(
        &config(dir),
        Some(&log),
        Some(RecordKey::read(&key).unwrap()),
    )
    .unwrap()
    .execute(&mut [], |_, _| {})
    .unwrap();
    (log, key, serde_json::to_string(&summary).unwrap())
}

fn lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

/// What a forger without the key does: edits the content of the lines and
/// recomputes the chain with `chain` (unkeyed, or keyed with his own key).
fn rechain(lines: &[String], mut chain: Chain) -> String {
    let mut out = String::new();
    for l in lines {
        let (_, content) = chain::split(l).unwrap();
        out.push_str(&chain.seal(&content, !content.contains(r#""record":"resumed""#)));
        out.push('\n');
    }
    out
}

/// The demo log's episode summaries with `r_task_avg` changed (the forgery
/// issue 31 item 30 reports).
fn forged_content(original: &[String]) -> Vec<String> {
    let mut lines = original.to_vec();
    let n = lines
        .iter()
        .position(|l| l.contains(r#""record":"episode_end""#))
        .unwrap();
    let at = lines[n].find(r#""r_task_avg":"#).unwrap() + r#""r_task_avg":"#.len();
    let end = at + lines[n][at..].find([',', '}']).unwrap();
    lines[n].replace_range(at..end, "0.999");
    lines
}

/// Expects opening `log` with `key` to be refused at `line`, field `field`.
fn assert_refused(log: &Path, key: Option<&Path>, line: usize, field: &str) {
    let key = key.map(|k| RecordKey::read(k).unwrap());
    let e = RecordLog::verify(log, key.clone()).unwrap_err();
    match &e {
        HilError::Data {
            path,
            record,
            field: f,
            ..
        } => {
            assert_eq!(path, log);
            assert_eq!((*record, f.as_str()), (line, field), "{e}");
        }
        other => panic!("expected a data error at line {line}, got {other:?}"),
    }
    // Resuming refuses it the same way.
    match Run::resume_with_key(log, key) {
        Err(HilError::Data {
            record, field: f, ..
        }) => assert_eq!((record, f.as_str()), (line, field)),
        other => panic!("resume: expected a data error at line {line}, got {other:?}"),
    }
}

#[test]
fn a_keyed_log_rechained_without_its_key_is_refused() {
    let dir = tmp_dir("unkeyed-forgery");
    let (log, key, _) = keyed_run(&dir);
    let forged = forged_content(&lines(&log));

    // Re-chained with the unkeyed algorithm, header unchanged: the header's
    // own HMAC does not verify.
    std::fs::write(&log, rechain(&forged, Chain::start())).unwrap();
    assert_refused(&log, Some(&key), 1, "chain");

    // ...and with the header's key id removed too: the key says the log
    // must be keyed.
    let mut stripped = forged.clone();
    let id = RecordKey::read(&key).unwrap().id();
    stripped[0] = stripped[0].replace(&format!(r#","record_key":"{id}""#), "");
    assert_ne!(stripped[0], forged[0]);
    std::fs::write(&log, rechain(&stripped, Chain::start())).unwrap();
    assert_refused(&log, Some(&key), 1, "record_key");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_keyed_log_rechained_with_another_key_is_refused() {
    let dir = tmp_dir("wrong-key");
    let (log, key, _) = keyed_run(&dir);
    let forged = forged_content(&lines(&log));
    let other_path = dir.join("other.key");
    let other = RecordKey::generate(&other_path).unwrap();

    // The forger's key, the original key id left in the header: the first
    // line's HMAC does not verify with the right key.
    std::fs::write(&log, rechain(&forged, Chain::start_keyed(other.clone()))).unwrap();
    assert_refused(&log, Some(&key), 1, "chain");

    // The forger's key and its id: the ids differ.
    let mut relabelled = forged.clone();
    let id = RecordKey::read(&key).unwrap().id();
    relabelled[0] = relabelled[0].replace(&id, &other.id());
    std::fs::write(&log, rechain(&relabelled, Chain::start_keyed(other))).unwrap();
    assert_refused(&log, Some(&key), 1, "record_key");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_keyed_log_edited_after_the_header_is_refused_at_that_line() {
    let dir = tmp_dir("edit");
    let (log, key, _) = keyed_run(&dir);
    let original = lines(&log);
    let forged = forged_content(&original);
    let n = (0..forged.len())
        .find(|&i| forged[i] != original[i])
        .unwrap();
    std::fs::write(&log, forged.join("\n") + "\n").unwrap();
    assert_refused(&log, Some(&key), n + 1, "chain");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_keyed_log_needs_its_key_and_an_unkeyed_log_refuses_one() {
    let dir = tmp_dir("need-key");
    let (log, key, _) = keyed_run(&dir);
    // Without the key: refused at the header, naming the log.
    assert_refused(&log, None, 1, "record_key");
    // A key given for an unkeyed log (what a forger who strips the keying
    // leaves) is refused too.
    let plain = dir.join("plain.jsonl");
    Run::from_config(&config(&dir), Some(&plain))
        .unwrap()
        .execute(&mut [], |_, _| {})
        .unwrap();
    assert_refused(&plain, Some(&key), 1, "record_key");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_right_key_verifies_and_resumes_to_the_identical_result() {
    let dir = tmp_dir("resume");
    let (log, key, summary) = keyed_run(&dir);
    let whole = lines(&log);
    let verified = RecordLog::verify(&log, Some(RecordKey::read(&key).unwrap())).unwrap();
    assert_eq!(verified.records.len() + 1, whole.len());
    for cut in (1..whole.len()).step_by(5) {
        let part = dir.join(format!("cut{cut}.jsonl"));
        std::fs::write(&part, whole[..cut].join("\n") + "\n").unwrap();
        let resumed = Run::resume_with_key(&part, Some(RecordKey::read(&key).unwrap()))
            .unwrap()
            .execute(&mut [], |_, _| {})
            .unwrap();
        assert_eq!(
            serde_json::to_string(&resumed).unwrap(),
            summary,
            "cut {cut}"
        );
        assert_eq!(lines_without_markers(&part), whole, "cut {cut}");
        // The appended lines (the marker included) verify with the key.
        RecordLog::verify(&part, Some(RecordKey::read(&key).unwrap())).unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unkeyed_header_line_is_written_as_before() {
    // The unkeyed format, pinned byte for byte: no `record_key` field, and
    // the chain is SHA-256(SHA-256(format name) || content).
    let dir = tmp_dir("unkeyed-bytes");
    let path = dir.join("log.jsonl");
    drop(RecordLog::create(&path, Header::new("seed = 1\n", "exp.toml", ".", 1, 2)).unwrap());
    let content = r#"{"record":"header","format":"hil-interaction-record","version":3,"seed":1,"episodes":2,"config_path":"exp.toml","base_dir":".","config":"seed = 1\n","config_digest":"46545c629053298cb8b068758bd6cb0ba83f1533f50a054de71575535afea66b"}"#;
    assert_eq!(
        chain::digest_hex("seed = 1\n"),
        "46545c629053298cb8b068758bd6cb0ba83f1533f50a054de71575535afea66b"
    );
    let start = sha2_hex(b"hil-interaction-record");
    let digest = sha2_hex(&[hex_bytes(&start), content.as_bytes().to_vec()].concat());
    let expected = format!(
        "{{\"chain\":\"{digest}\",{}\n",
        content.strip_prefix('{').unwrap()
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn sha2_hex(bytes: &[u8]) -> String {
    // The one SHA-256 helper hil exposes hashes text; the chain hashes bytes.
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn hex_bytes(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}
