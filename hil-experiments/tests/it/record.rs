//! The interaction record: durable logging, and resuming a session cut off
//! at every possible point, checked against an uninterrupted run.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::channel::PerfectExpert;
use hil_core::{
    ActionSpace, Answer, ArmId, Choice, HilError, Query, QueryChannel, QueryKind, Response,
    ResponseType, SessionSettings,
};
use hil_experiments::Experiment;
use hil_experiments::run_recorded;
use hil_record::{Header, Record, RecordLog};

use crate::demo::lines_without_markers;

fn tmp_dir(name: &str) -> PathBuf {
    // tmpfs where available: these tests fsync thousands of lines, which on
    // a disk costs seconds and tests nothing more.
    let shm = Path::new("/dev/shm");
    let base = if shm.is_dir() {
        shm.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    let d = base.join(format!("hil-record-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A channel that answers like the oracle but declines at timesteps that are
/// multiples of 3 (its answers depend only on the query, like a simulated
/// expert's, so an uninterrupted run can be compared), and remembers every query it was asked (to prove nobody is asked twice).
struct Person {
    asked: Arc<Mutex<Vec<u64>>>,
}

impl QueryChannel for Person {
    fn name(&self) -> &str {
        "person"
    }
    fn ask(&mut self, q: &Query) -> hil_core::Result<Response> {
        let mut asked = self.asked.lock().unwrap();
        asked.push(q.t);
        if q.t % 3 == 0 {
            return Ok(Response::without_action(Answer::Declined));
        }
        let mut r = PerfectExpert::default().ask(q)?;
        r.response_time_s = Some(0.1 * q.t as f64 + 1.0 / 3.0);
        Ok(r)
    }
}

fn experiment(asked: Arc<Mutex<Vec<u64>>>) -> Experiment {
    let actions = ActionSpace::new(["A", "B", "C"]).unwrap();
    let env = TableEnv::new(
        actions,
        vec![
            ("kiwi", vec![0.2, 0.7, 0.4]),
            ("carrot", vec![0.1, 0.3, 0.6]),
            ("kiwi", vec![0.2, 0.7, 0.4]),
            ("grape", vec![0.5, 0.5, 0.5]),
        ],
    )
    .unwrap();
    let ask = |response| Choice::Query {
        kind: QueryKind {
            response,
            ..Default::default()
        },
        fallback: ArmId(0),
    };
    let policy = ScriptedPolicy::new(
        3,
        5,
        vec![
            ask(ResponseType::Mcq),
            Choice::Act { arm: ArmId(0) },
            ask(ResponseType::BoundingBox),
            Choice::Act { arm: ArmId(2) },
            ask(ResponseType::OpenEnded),
            Choice::Act { arm: ArmId(1) },
            Choice::Act { arm: ArmId(0) },
        ],
    );
    Experiment {
        settings: SessionSettings::default()
            .with_n_att(3)
            .with_wl0(0.5)
            .with_max_items(None),
        seed: 42,
        episodes: 3,
        environment: Box::new(env),
        policy: Box::new(policy),
        channel: Box::new(Person { asked }),
        workload: Arc::new(CountingWorkload::new(0.05)),
        forecast: None,
    }
}

fn header() -> Header {
    Header::new("seed = 42\nepisodes = 3\n", "exp.toml", ".", 42, 3)
}

/// Runs a full recorded session into `path`.
fn full_run(path: &Path) -> Vec<hil_core::EpisodeMetrics> {
    let mut exp = experiment(Arc::default());
    let log = RecordLog::create(path, header()).unwrap();
    let mut seen = Vec::new();
    run_recorded(&mut exp, log, None, &mut [], |_, m| seen.push(m.clone())).unwrap();
    seen
}

#[test]
fn a_recorded_run_matches_an_unrecorded_one() {
    let dir = tmp_dir("plain");
    let path = dir.join("log.jsonl");
    let recorded = full_run(&path);
    let mut exp = experiment(Arc::default());
    let mut collector = hil_core::EventCollector::default();
    let summary = exp.run(&mut [&mut collector], |_, _| {}).unwrap();
    assert_eq!(summary.episodes, recorded);

    let (_, logged) = RecordLog::open(&path).unwrap();
    let events: Vec<_> = logged.events().into_iter().map(|(_, e)| e).collect();
    assert_eq!(events, collector.events);
    // Every kind of record is there, and the query kinds are stored.
    let kinds: Vec<&str> = logged.records.iter().map(|r| r.record.kind()).collect();
    for k in [
        "episode_start",
        "step",
        "outcome",
        "episode_end",
        "checkpoint",
    ] {
        assert!(kinds.contains(&k), "{k} missing");
    }
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(r#""response":"bounding_box""#));
    assert!(text.contains(r#""type":"declined""#));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resuming_from_every_cut_point_gives_the_uninterrupted_log() {
    let dir = tmp_dir("cuts");
    let reference_path = dir.join("reference.jsonl");
    let reference_metrics = full_run(&reference_path);
    let reference = lines_without_markers(&reference_path);
    let bytes = std::fs::read(&reference_path).unwrap();
    // Cut at every line end and in the middle of every line: what a kill at
    // any moment can leave (a step written but not acted on, a torn write...).
    let mut cuts = Vec::new();
    let mut start = 0;
    for (i, b) in bytes.iter().enumerate() {
        if *b == b'\n' {
            cuts.push((start + i).div_ceil(2));
            cuts.push(i + 1);
            start = i + 1;
        }
    }
    let header_end = bytes.iter().position(|b| *b == b'\n').unwrap() + 1;
    let path = dir.join("cut.jsonl");
    for cut in cuts.into_iter().filter(|c| *c >= header_end) {
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let (log, logged) = RecordLog::open(&path).unwrap();
        // Queries answered in the log must not be asked again.
        let logged_queries: Vec<u64> = logged
            .records
            .iter()
            .filter_map(|r| match &r.record {
                Record::Step { step, episode } if step.response.is_some() => {
                    Some((*episode, step.t))
                }
                _ => None,
            })
            .map(|(_, t)| t)
            .collect();
        let asked = Arc::new(Mutex::new(Vec::new()));
        let mut exp = experiment(asked.clone());
        let mut metrics = Vec::new();
        run_recorded(&mut exp, log, Some(&logged), &mut [], |_, m| {
            metrics.push(m.clone())
        })
        .unwrap_or_else(|e| panic!("resume after cut at byte {cut}: {e}"));
        assert_eq!(metrics, reference_metrics, "cut at byte {cut}");
        assert_eq!(lines_without_markers(&path), reference, "cut at byte {cut}");
        let reference_queries = reference
            .iter()
            .filter(|l| l.contains(r#""record":"step""#) && l.contains(r#""response":{"#))
            .count();
        assert_eq!(
            asked.lock().unwrap().len() + logged_queries.len(),
            reference_queries,
            "cut at byte {cut}: a person was asked again or not at all"
        );
        // The marker says where the session picked up.
        let text = std::fs::read_to_string(&path).unwrap();
        let markers = text.matches(r#""record":"resumed""#).count();
        assert!(markers <= 1, "cut at byte {cut}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_diverging_replay_is_refused_with_the_line() {
    let dir = tmp_dir("diverge");
    let path = dir.join("log.jsonl");
    full_run(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    // Cut before the first checkpoint, so that the first episode is
    // replayed, and resume with a policy that acts differently (a plugin or
    // the code changed): the first autonomous step diverges.
    let first_checkpoint = text
        .lines()
        .position(|l| l.contains(r#""record":"checkpoint""#))
        .unwrap();
    let kept: Vec<&str> = text.lines().take(first_checkpoint).collect();
    std::fs::write(&path, kept.join("\n") + "\n").unwrap();
    let first_act = kept
        .iter()
        .position(|l| l.contains(r#""decision":{"type":"act""#))
        .unwrap();
    let (log, logged) = RecordLog::open(&path).unwrap();
    let mut exp = experiment(Arc::default());
    exp.policy = Box::new(ScriptedPolicy::new(
        3,
        5,
        vec![Choice::Act { arm: ArmId(2) }],
    ));
    let err = run_recorded(&mut exp, log, Some(&logged), &mut [], |_, _| {}).unwrap_err();
    match &err {
        HilError::Data { record, why, .. } => {
            assert!(*record <= first_act + 1, "{err}");
            assert!(why.contains("diverged"), "{why}");
        }
        other => panic!("{other}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The line number (1-based) and text of the first line containing `pat`.
fn find_line(lines: &[String], pat: &str) -> usize {
    lines.iter().position(|l| l.contains(pat)).unwrap() + 1
}

/// Writes `lines` to `path` and expects `RecordLog::open` to refuse it at
/// `line`, field `field`.
fn assert_refused(path: &Path, lines: &[String], line: usize, field: &str) {
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
    match RecordLog::open(path).unwrap_err() {
        HilError::Data {
            path: p,
            record,
            field: f,
            ..
        } => {
            assert_eq!(p, path);
            assert_eq!((record, f.as_str()), (line, field));
        }
        other => panic!("expected a data error at line {line}, got {other:?}"),
    }
}

fn log_lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn a_changed_byte_before_the_last_checkpoint_is_refused_with_its_line() {
    let dir = tmp_dir("tamper");
    let path = dir.join("log.jsonl");
    full_run(&path);
    let original = log_lines(&path);

    // A flipped bit in the first episode's metrics (restored, not replayed,
    // on resume: before the chain, this changed the result silently).
    let mut lines = original.clone();
    let n = find_line(&lines, r#""record":"episode_end""#);
    let at = lines[n - 1].find(r#""n_steps":"#).unwrap() + r#""n_steps":"#.len();
    let mut bytes = lines[n - 1].clone().into_bytes();
    bytes[at] ^= 0x01; // a digit stays a digit: still a valid record
    lines[n - 1] = String::from_utf8(bytes).unwrap();
    assert_refused(&path, &lines, n, "chain");

    // An edited checkpoint.
    let mut lines = original.clone();
    let n = find_line(&lines, r#""record":"checkpoint""#);
    lines[n - 1] = lines[n - 1].replacen(r#""policy":"#, r#""policy":{"edited":true},"x":"#, 1);
    assert_refused(&path, &lines, n, "chain");

    // A removed line.
    let mut lines = original.clone();
    lines.remove(5);
    assert_refused(&path, &lines, 6, "chain");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_header_from_another_log_or_an_edited_config_is_refused() {
    let dir = tmp_dir("splice");
    let path = dir.join("log.jsonl");
    full_run(&path);
    let original = log_lines(&path);

    // The header of another session (another config), spliced on.
    let other = dir.join("other.jsonl");
    let mut exp = experiment(Arc::default());
    exp.seed = 7;
    let h = Header::new("seed = 7\nepisodes = 3\n", "exp.toml", ".", 7, 3);
    run_recorded(
        &mut exp,
        RecordLog::create(&other, h).unwrap(),
        None,
        &mut [],
        |_, _| {},
    )
    .unwrap();
    let mut lines = original.clone();
    lines[0] = log_lines(&other)[0].clone();
    assert_refused(&path, &lines, 2, "chain");

    // The config edited in place: its digest no longer matches...
    let mut lines = original.clone();
    lines[0] = lines[0].replacen("episodes = 3", "episodes = 4", 1);
    assert_refused(&path, &lines, 1, "config_digest");
    // ...and with the digest edited to match, the chain does not.
    let new_digest = hil_record::chain::digest_hex("seed = 42\nepisodes = 4\n");
    let old_digest = hil_record::chain::digest_hex("seed = 42\nepisodes = 3\n");
    lines[0] = lines[0].replacen(&old_digest, &new_digest, 1);
    assert_refused(&path, &lines, 1, "chain");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_log_has_one_writer_and_the_second_is_told_who_holds_it() {
    let dir = tmp_dir("lock");
    let path = dir.join("log.jsonl");
    let first = RecordLog::create(&path, header()).unwrap();
    let owner = hil_record::lock::owner_path(&path);
    assert!(owner.is_file());
    for _ in 0..2 {
        match RecordLog::open(&path).unwrap_err() {
            HilError::Io {
                path: p, source, ..
            } => {
                assert_eq!(p, path);
                assert_eq!(source.kind(), std::io::ErrorKind::WouldBlock);
                let why = source.to_string();
                assert!(
                    why.contains(&format!("process {}", std::process::id())),
                    "{why}"
                );
            }
            other => panic!("expected a lock error, got {other:?}"),
        }
    }
    drop(first);
    assert!(!owner.exists(), "the owner file goes with the writer");
    let (second, _) = RecordLog::open(&path).unwrap();
    assert!(RecordLog::open(&path).is_err());
    drop(second);
    RecordLog::open(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn only_regular_files_of_bounded_size_are_read_as_logs() {
    // (No FIFO here: making one means spawning `mkfifo`, and a child
    // between fork and exec shares this process's locks, which would race
    // with the other tests' logs.)
    let dir = tmp_dir("special");
    for p in [PathBuf::from("/dev/zero"), dir.clone()] {
        match RecordLog::open(&p) {
            Err(HilError::Io { path, .. }) => assert_eq!(path, p),
            other => panic!("{}: expected an I/O error, got {other:?}", p.display()),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_logs_are_rejected_with_file_line_and_field() {
    let dir = tmp_dir("malformed");
    let path = dir.join("log.jsonl");
    full_run(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[3] = "{not json".into();
    assert_refused(&path, &lines, 4, "chain");
    // A well-formed chain field in front of junk: the record is at fault.
    lines[3] = format!(r#"{{"chain":"{}",not json"#, "0".repeat(64));
    assert_refused(&path, &lines, 4, "record");

    assert_refused(
        &path,
        &["{\"record\":\"episode_start\",\"episode\":0,\"seed\":1}".into()],
        1,
        "record",
    );

    // Killed while writing the header: nothing to resume, and it says so.
    std::fs::write(&path, "{\"record\":\"hea").unwrap();
    let err = RecordLog::open(&path).unwrap_err().to_string();
    assert!(err.contains("start it again"), "{err}");

    // An existing log is never overwritten.
    let err = RecordLog::create(&path, header()).unwrap_err().to_string();
    assert!(err.contains("log.jsonl"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_finished_log_resumes_to_the_same_summary_without_running_anything() {
    let dir = tmp_dir("finished");
    let path = dir.join("log.jsonl");
    let reference = full_run(&path);
    let before = std::fs::read_to_string(&path).unwrap();
    let (log, logged) = RecordLog::open(&path).unwrap();
    let asked = Arc::new(Mutex::new(Vec::new()));
    let summary = run_recorded(
        &mut experiment(asked.clone()),
        log,
        Some(&logged),
        &mut [],
        |_, _| {},
    )
    .unwrap();
    assert_eq!(summary.episodes, reference);
    assert!(asked.lock().unwrap().is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_step_that_cannot_be_logged_stops_the_session_before_the_robot_acts() {
    use hil_core::{ArmDiagnostics, Diagnostics, PendingStep, SessionObserver, StepDecision};
    use hil_record::Recorder;
    let dir = tmp_dir("nan");
    let path = dir.join("log.jsonl");
    let mut rec = Recorder::new(RecordLog::create(&path, header()).unwrap());
    let step = PendingStep {
        t: 1,
        item_index: 0,
        item_label: "kiwi".into(),
        attempt: 0,
        context: hil_core::Context::new(vec![0.0]).unwrap(),
        decision: StepDecision::Act { arm: ArmId(0) },
        diagnostics: Some(Diagnostics::new().with_arms(vec![ArmDiagnostics::new(
            f64::NAN,
            0.0,
            0.0,
        )])),
        response: None,
        arm: ArmId(0),
        wl_t: 0.5,
    };
    let err = rec.before_execute(&step).unwrap_err();
    assert!(matches!(err, HilError::InvalidInput { .. }), "{err}");
    assert!(err.to_string().len() < 500, "no dump of the record: {err}");
    drop(rec);
    // Nothing unreadable reached the log.
    let (_, logged) = RecordLog::open(&path).unwrap();
    assert!(logged.records.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_log_of_the_previous_format_version_is_refused_and_says_why() {
    let dir = tmp_dir("version");
    let path = dir.join("log.jsonl");
    full_run(&path);
    let text = std::fs::read_to_string(&path).unwrap();
    let current = format!(r#""version":{}"#, hil_record::FORMAT_VERSION);
    assert!(text.contains(&current));
    // Every older version (and a newer one) is refused before anything
    // else in the log is read, saying which version it is.
    for v in (1..hil_record::FORMAT_VERSION).chain([99]) {
        let old = format!(r#""version":{v}"#);
        std::fs::write(&path, text.replacen(&current, &old, 1)).unwrap();
        match RecordLog::open(&path).unwrap_err() {
            HilError::Data {
                record, field, why, ..
            } => {
                assert_eq!((record, field.as_str()), (1, "version"));
                assert!(why.contains(&format!("version {v}")), "{why}");
            }
            e => panic!("expected a data error, got {e:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
