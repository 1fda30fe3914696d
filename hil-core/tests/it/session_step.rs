//! The steppable session: an outside loop driving `next_decision` /
//! `feed_decision` produces exactly what `run_episode` does (events,
//! metrics, what the policy learns, the interaction log byte for byte),
//! and every call out of order is a state error that leaves the episode
//! usable.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::channel::PerfectExpert;
use hil_core::{
    ActionSpace, ArmId, Choice, Decision, Episode, EpisodeReport, EventCollector, HilError, Policy,
    Session, SessionObserver, SessionSettings,
};
use hil_record::{Header, RecordLog, Recorder};

use crate::choices::{act, query};

/// Acts, asks (the expert's arm then repeats) and fails items out: every
/// path through an item.
fn script() -> Vec<Choice> {
    vec![act(0), query(0), act(2), act(2), query(1), act(1), act(0)]
}

fn env() -> TableEnv {
    TableEnv::new(
        ActionSpace::new(["A", "B", "C"]).unwrap(),
        vec![
            ("apple", vec![0.2, 0.9, 0.5]),
            ("banana", vec![0.6, 0.1, 0.3]),
            ("carrot", vec![0.1, 0.2, 0.3]),
            ("kiwi", vec![0.3, 0.3, 0.3]),
            ("grape", vec![0.5, 0.4, 0.1]),
        ],
    )
    .unwrap()
}

/// The context dimension of [`env`].
fn dim() -> usize {
    hil_core::Environment::context_dim(&env())
}

fn settings() -> SessionSettings {
    SessionSettings::default().with_n_att(3)
}

/// A fresh log path per call (tests run in parallel).
fn log_path(name: &str) -> PathBuf {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("hil-session-step-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{}-{name}", CALLS.fetch_add(1, Ordering::Relaxed)));
    let _ = std::fs::remove_file(&path);
    path
}

/// A recorder writing to a fresh log at `path`.
fn recorder(path: &Path) -> Recorder {
    let log = RecordLog::create(path, Header::new("seed = 3", "exp.toml", ".", 3, 1)).unwrap();
    let mut r = Recorder::new(log);
    r.set_episode(0);
    r
}

/// What a run left behind: its report, the observer's events, what the
/// policy learned and the log's bytes.
struct Trace {
    report: EpisodeReport,
    collected: usize,
    feedback: Vec<(u64, ArmId, f64, bool)>,
    log: Vec<u8>,
}

/// Runs the scripted episode; `outside` drives it by the step API with an
/// agent of its own, otherwise `run_episode` does with the session's
/// policy.
fn run(outside: bool, name: &str) -> Trace {
    let mut env = env();
    let mut policy = ScriptedPolicy::new(3, dim(), script());
    let mut channel = PerfectExpert::default();
    let path = log_path(name);
    let mut rec = recorder(&path);
    let mut collector = EventCollector::default();
    let report = {
        let mut observers: [&mut dyn SessionObserver; 2] = [&mut rec, &mut collector];
        let mut session = Session::new(
            settings(),
            &mut env,
            &mut policy,
            &mut channel,
            Arc::new(CountingWorkload::new(0.1)),
        );
        if outside {
            // The agent decides outside the session; the session's policy
            // is taught every outcome, as in `run_episode`.
            let mut agent = ScriptedPolicy::new(3, dim(), script());
            let mut episode = session.start_episode(11, &mut observers).unwrap();
            while let Some(input) = session.next_decision(&mut episode, &mut observers).unwrap() {
                let decision = agent.decide(&input).unwrap();
                session
                    .feed_decision(&mut episode, decision, &mut observers)
                    .unwrap();
            }
            session
                .finish_episode(&mut episode, &mut observers)
                .unwrap()
        } else {
            session.run_episode(11, &mut observers).unwrap()
        }
    };
    drop(rec);
    let log = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    Trace {
        collected: collector.events.len(),
        report,
        feedback: policy.feedback,
        log,
    }
}

#[test]
fn an_outside_loop_gives_exactly_what_run_episode_gives() {
    let inside = run(false, "inside.jsonl");
    let outside = run(true, "outside.jsonl");
    assert!(inside.report.metrics.n_q >= 2, "the script asks");
    assert!(
        inside
            .report
            .events
            .iter()
            .any(|e| matches!(e.step.decision, hil_core::StepDecision::FollowExpert { .. })),
        "the expert's arm is repeated"
    );
    assert_eq!(outside.report.events, inside.report.events);
    assert_eq!(outside.collected, inside.report.events.len());
    assert_eq!(
        serde_json::to_string(&outside.report.metrics).unwrap(),
        serde_json::to_string(&inside.report.metrics).unwrap()
    );
    assert_eq!(outside.feedback, inside.feedback);
    assert!(!inside.log.is_empty());
    assert_eq!(
        String::from_utf8(outside.log).unwrap(),
        String::from_utf8(inside.log).unwrap()
    );
}

#[test]
fn step_is_one_decision_of_the_sessions_policy() {
    let mut env = env();
    let mut policy = ScriptedPolicy::new(3, dim(), script());
    let mut channel = PerfectExpert::default();
    let mut session = Session::new(
        settings(),
        &mut env,
        &mut policy,
        &mut channel,
        Arc::new(CountingWorkload::new(0.1)),
    );
    let mut episode = session.start_episode(11, &mut []).unwrap();
    let mut decisions = 0;
    while session.step(&mut episode, &mut []).unwrap() {
        decisions += 1;
        // Each step ends at the executed decision; the expert's repeats
        // run at the next one.
        assert!(episode.events().last().unwrap().step.diagnostics.is_some());
    }
    assert!(episode.is_over());
    assert!(!session.step(&mut episode, &mut []).unwrap(), "stays over");
    let report = session.finish_episode(&mut episode, &mut []).unwrap();
    let consulted = report
        .events
        .iter()
        .filter(|e| e.step.diagnostics.is_some())
        .count();
    assert_eq!(decisions, consulted);
    assert_eq!(report.events, run(false, "step.jsonl").report.events);
}

/// The error of an out-of-order call: a state error naming the call.
fn assert_state(e: HilError, call: &str) {
    assert!(
        matches!(e, HilError::State { .. }) && e.to_string().contains(call),
        "{e}"
    );
}

/// A session over the scripted episode, for the order tests.
fn with_session(f: impl FnOnce(&mut Session<'_>)) {
    let mut env = env();
    let mut policy = ScriptedPolicy::new(3, dim(), script());
    let mut channel = PerfectExpert::default();
    let mut session = Session::new(
        settings(),
        &mut env,
        &mut policy,
        &mut channel,
        Arc::new(CountingWorkload::new(0.1)),
    );
    f(&mut session);
}

/// Finishes `episode` by its session's own policy and checks it is the
/// uninterrupted episode.
/// Feeds the policy's answer to the awaited decision, then finishes as
/// [`finish_normally`] does: the episode recovered from a refused call.
fn answer_pending_and_finish(session: &mut Session<'_>, episode: &mut Episode) {
    let decision = session.policy.decide(&episode.pending().unwrap()).unwrap();
    session.feed_decision(episode, decision, &mut []).unwrap();
    finish_normally(session, episode);
}

fn finish_normally(session: &mut Session<'_>, episode: &mut Episode) {
    while session.step(episode, &mut []).unwrap() {}
    let report = session.finish_episode(episode, &mut []).unwrap();
    assert_eq!(report.events, run(false, "reference.jsonl").report.events);
}

#[test]
fn feeding_a_decision_before_one_is_asked_is_a_state_error() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        let e = session
            .feed_decision(&mut episode, Decision::act(ArmId(0)), &mut [])
            .unwrap_err();
        assert_state(e, "feed_decision");
        assert!(episode.events().is_empty());
        finish_normally(session, &mut episode);
    });
}

#[test]
fn feeding_a_second_decision_is_a_state_error() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        session
            .next_decision(&mut episode, &mut [])
            .unwrap()
            .unwrap();
        session
            .feed_decision(&mut episode, Decision::act(ArmId(0)), &mut [])
            .unwrap();
        let e = session
            .feed_decision(&mut episode, Decision::act(ArmId(0)), &mut [])
            .unwrap_err();
        assert_state(e, "feed_decision");
        assert_eq!(episode.events().len(), 1);
        // The session's policy decides the rest; its script starts over,
        // so only the first step is compared.
        while session.step(&mut episode, &mut []).unwrap() {}
        assert!(episode.is_over());
    });
}

#[test]
fn asking_again_while_a_decision_is_awaited_is_a_state_error() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        let t = session
            .next_decision(&mut episode, &mut [])
            .unwrap()
            .unwrap()
            .t;
        let e = session.next_decision(&mut episode, &mut []).unwrap_err();
        assert_state(e, "next_decision");
        // `step` asks first, so it is refused too.
        assert_state(
            session.step(&mut episode, &mut []).unwrap_err(),
            "next_decision",
        );
        // The awaited decision is still the same one.
        assert_eq!(episode.pending().unwrap().t, t);
        answer_pending_and_finish(session, &mut episode);
    });
}

#[test]
fn finishing_before_the_last_item_is_a_state_error() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        assert_state(
            session.finish_episode(&mut episode, &mut []).unwrap_err(),
            "finish_episode",
        );
        session.next_decision(&mut episode, &mut []).unwrap();
        assert_state(
            session.finish_episode(&mut episode, &mut []).unwrap_err(),
            "finish_episode",
        );
        answer_pending_and_finish(session, &mut episode);
    });
}

#[test]
fn a_finished_episode_takes_no_more_calls() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        finish_normally(session, &mut episode);
        assert_state(
            session.finish_episode(&mut episode, &mut []).unwrap_err(),
            "finish_episode",
        );
        assert_state(
            session.next_decision(&mut episode, &mut []).unwrap_err(),
            "next_decision",
        );
        assert_state(
            session
                .feed_decision(&mut episode, Decision::act(ArmId(0)), &mut [])
                .unwrap_err(),
            "feed_decision",
        );
    });
}

#[test]
fn a_failed_step_ends_the_episode() {
    with_session(|session| {
        let mut episode = session.start_episode(11, &mut []).unwrap();
        session.next_decision(&mut episode, &mut []).unwrap();
        // Arm 7 of 3: the step fails, as `run_episode` would.
        let e = session
            .feed_decision(&mut episode, Decision::act(ArmId(7)), &mut [])
            .unwrap_err();
        assert!(!matches!(e, HilError::State { .. }), "{e}");
        let e = session.next_decision(&mut episode, &mut []).unwrap_err();
        assert!(e.to_string().contains("an earlier step failed"), "{e}");
        assert_state(
            session.finish_episode(&mut episode, &mut []).unwrap_err(),
            "finish_episode",
        );
    });
}
