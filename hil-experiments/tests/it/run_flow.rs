//! The run/resume flow of `hil run` and hil-py (`hil_experiments::run`):
//! a log cut anywhere resumes to the uninterrupted log and summary, a log
//! has one writer, and the step events written as JSONL are the session's.

use std::path::{Path, PathBuf};

use hil_core::EventCollector;
use hil_experiments::run::{JsonlEvents, Recording, Run};

const CONFIG: &str = r#"
seed = 5
episodes = 2

[session]
n_att = 3

[environment]
type = "demo_plate"
foods = ["banana", "carrot", "grape"]
repeat = 2

[policy]
type = "demo_learner"
query_probability = 0.5
epsilon = 0.2

[workload]
type = "demo_counting"
increment = 0.05
window = 10

[channel]
type = "simulated_expert"
decline_rate = 0.2
"#;

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-run-flow-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes the config into `dir` and returns its path.
fn config(dir: &Path) -> PathBuf {
    let path = dir.join("exp.toml");
    std::fs::write(&path, CONFIG).unwrap();
    path
}

fn lines_without_markers(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.contains(r#""record":"resumed""#))
        .map(String::from)
        .collect()
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
    assert_eq!(header["config"], CONFIG);
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
