//! The run/resume flow of `hil run` and hil-py (`hil_experiments::run`):
//! a log cut anywhere resumes to the uninterrupted log and summary, a log
//! has one writer, and the step events written as JSONL are the session's.

use std::path::{Path, PathBuf};

use hil_core::{EventCollector, HilError};
use hil_experiments::run::{JsonlEvents, Recording, Run};

use crate::demo::{DemoSession, lines_without_markers, scratch_dir};

/// The session every test here runs.
fn config_text() -> String {
    DemoSession::default().toml()
}

fn tmp_dir(name: &str) -> PathBuf {
    scratch_dir("run-flow", name)
}

/// Writes the config into `dir` and returns its path.
fn config(dir: &Path) -> PathBuf {
    let path = dir.join("exp.toml");
    std::fs::write(&path, config_text()).unwrap();
    path
}

#[test]
fn a_log_cut_anywhere_resumes_to_the_uninterrupted_run() {
    let dir = tmp_dir("cut");
    let config = config(&dir);
    let plain = Run::from_config(&config, None)
        .unwrap()
        .execute(&mut [], |_, _| {})
        .unwrap();
    let full = dir.join("full.jsonl");
    let run = Run::from_config(&config, Some(&full)).unwrap();
    assert!(matches!(run.recording, Recording::New(_)));
    let recorded = run.execute(&mut [], |_, _| {}).unwrap();
    assert_eq!(
        serde_json::to_string(&recorded).unwrap(),
        serde_json::to_string(&plain).unwrap()
    );
    let lines = lines_without_markers(&full);
    assert!(lines.len() > 20, "{} lines", lines.len());
    // The header holds the config verbatim and where it was.
    let header: serde_json::Value = serde_json::from_str(&lines[0]).unwrap();
    assert_eq!(header["config"], config_text());
    let config_path = PathBuf::from(header["config_path"].as_str().unwrap());
    assert!(config_path.is_absolute());

    for cut in (1..lines.len()).step_by(7) {
        let log = dir.join(format!("cut{cut}.jsonl"));
        std::fs::write(&log, lines[..cut].join("\n") + "\n").unwrap();
        let run = Run::resume(&log).unwrap();
        assert_eq!(run.recording.logged().unwrap().records.len(), cut - 1);
        let mut episodes = Vec::new();
        let summary = run.execute(&mut [], |k, _| episodes.push(k)).unwrap();
        assert_eq!(episodes, [0, 1], "cut at {cut}");
        assert_eq!(
            serde_json::to_string(&summary).unwrap(),
            serde_json::to_string(&plain).unwrap(),
            "cut at {cut}"
        );
        assert_eq!(lines_without_markers(&log), lines, "cut at {cut}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_log_has_one_writer() {
    let dir = tmp_dir("writer");
    let config = config(&dir);
    let log = dir.join("session.jsonl");
    let first = Run::from_config(&config, Some(&log)).unwrap();
    let e = Run::resume(&log).unwrap_err().to_string();
    assert!(e.contains("session.jsonl"), "{e}");
    // A new run refuses an existing log too.
    assert!(Run::from_config(&config, Some(&log)).is_err());
    drop(first);
    Run::resume(&log).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn only_an_opened_log_can_be_resumed() {
    let e = Run::resume_from(Recording::Off).unwrap_err().to_string();
    assert!(e.contains("opened from a log"), "{e}");
}

#[test]
fn step_events_are_written_as_json_lines() {
    let dir = tmp_dir("events");
    let config = config(&dir);
    let path = dir.join("events.jsonl");
    let mut sink = JsonlEvents::create(&path).unwrap();
    let mut collector = EventCollector::default();
    Run::from_config(&config, None)
        .unwrap()
        .execute(&mut [&mut sink, &mut collector], |_, _| {})
        .unwrap();
    sink.finish().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let written: Vec<hil_core::StepEvent> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(!written.is_empty());
    assert_eq!(written, collector.events);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_config_is_an_error_naming_it() {
    let e = Run::from_config(Path::new("/nonexistent/exp.toml"), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/exp.toml"), "{e}");
}

/// `lines` with `edit` applied to each record's JSON text, re-chained as
/// a forger who knows the format would (the chain has no key).
fn forge(lines: &[String], mut edit: impl FnMut(usize, String) -> String) -> String {
    use hil_record::chain::{Chain, split};
    let mut chain = Chain::start();
    let mut out = String::new();
    for (i, line) in lines.iter().enumerate() {
        let (_, content) = split(line).unwrap();
        out += &chain.seal(&edit(i, content), true);
        out.push('\n');
    }
    out
}

/// A re-chained log whose episode summary disagrees with its steps, or
/// whose header's config was changed, is refused on resume, naming the line
/// and record where the replay departs from it (resuming used to trust
/// everything before the last checkpoint).
#[test]
fn a_forged_summary_or_header_is_refused_on_resume() {
    let dir = tmp_dir("forged");
    let config = config(&dir);
    let full = dir.join("full.jsonl");
    Run::from_config(&config, Some(&full))
        .unwrap()
        .execute(&mut [], |_, _| {})
        .unwrap();
    let lines = lines_without_markers(&full);
    assert!(lines.iter().any(|l| l.contains(r#""record":"checkpoint""#)));
    let end0 = lines
        .iter()
        .position(|l| l.contains(r#""record":"episode_end""#))
        .unwrap();

    let summary = dir.join("summary.jsonl");
    std::fs::write(
        &summary,
        forge(&lines, |i, content| {
            if i != end0 {
                return content;
            }
            let at = content.find("\"r_task_avg\":").unwrap() + "\"r_task_avg\":".len();
            let end = at + content[at..].find([',', '}']).unwrap();
            format!("{}0.999{}", &content[..at], &content[end..])
        }),
    )
    .unwrap();
    match Run::resume(&summary).unwrap().execute(&mut [], |_, _| {}) {
        Err(HilError::Data { record, field, .. }) => {
            assert_eq!((record, field.as_str()), (end0 + 1, "episode_end"))
        }
        other => panic!("{other:?}"),
    }

    let header = dir.join("header.jsonl");
    let digest = |cfg: &str| hil_record::chain::digest_hex(cfg);
    let original = config_text();
    let changed = original.replace("n_att = 3", "n_att = 4");
    std::fs::write(
        &header,
        forge(&lines, |i, content| {
            if i != 0 {
                return content;
            }
            let edited = content
                .replace("n_att = 3", "n_att = 4")
                .replace(&digest(&original), &digest(&changed));
            assert_ne!(edited, content);
            edited
        }),
    )
    .unwrap();
    match Run::resume(&header).unwrap().execute(&mut [], |_, _| {}) {
        Err(HilError::Data { record, .. }) => assert!(record > 1 && record <= lines.len()),
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
