//! Session-loop semantics on a hand-worked episode.

use std::sync::Arc;

use hil_core::channel::PerfectExpert;

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::{
    ActionSpace, Answer, ArmId, Choice, EpisodeReport, EventCollector, Query, QueryChannel,
    Response, Session, SessionObserver, SessionSettings, StepDecision,
};

fn actions() -> ActionSpace {
    ActionSpace::new(["A", "B", "C"]).unwrap()
}

/// Runs one episode with a counting workload model (+`inc` per query).
fn episode(
    env: &mut TableEnv,
    policy: &mut ScriptedPolicy,
    channel: &mut dyn QueryChannel,
    settings: SessionSettings,
    inc: f64,
    seed: u64,
    observers: &mut [&mut dyn SessionObserver],
) -> EpisodeReport {
    Session::new(
        settings,
        env,
        policy,
        channel,
        Arc::new(CountingWorkload::new(inc)),
    )
    .run_episode(seed, observers)
    .unwrap()
}

use crate::choices::{act, query};

/// The hand-worked episode (N_att = 3, WL_0 = 0.5, +0.1 per query):
///
/// | t | item   | decision        | arm | p(arm) | success | WL  |
/// |---|--------|-----------------|-----|--------|---------|-----|
/// | 1 | apple  | act A           | A   | 0.2    | no      | 0.5 |
/// | 2 | apple  | query → B       | B   | 0.9    | no      | 0.6 |
/// | 3 | apple  | follow expert B | B   | 0.9    | yes     | 0.6 |
/// | 4 | banana | act A           | A   | 0.6    | yes     | 0.6 |
/// | 5 | carrot | act C           | C   | 0.3    | no      | 0.6 |
/// | 6 | carrot | act C           | C   | 0.3    | no      | 0.6 |
/// | 7 | carrot | act B           | B   | 0.2    | no      | 0.6 |
///
/// r_task_avg = 3.4 / 7; ΔWL = 0.1; M_wt(0.7) = 0.34 − 0.03 = 0.31;
/// t_conv = 7 / 3; f_q = f_fail = f_auto = 1/3; n_success = 2; n_q = 1.
#[test]
fn hand_worked_episode() {
    let mut env = TableEnv::new(
        actions(),
        vec![
            ("apple", vec![0.2, 0.9, 0.5]),
            ("banana", vec![0.6, 0.1, 0.3]),
            ("carrot", vec![0.1, 0.2, 0.3]),
        ],
    )
    .unwrap()
    .with_outcomes(vec![false, false, true, true, false, false, false]);
    let dim = 5;
    let mut policy = ScriptedPolicy::new(
        3,
        dim,
        vec![act(0), query(0), act(0), act(2), act(2), act(1)],
    );
    let mut channel = PerfectExpert::default();
    let mut collector = EventCollector::default();
    let report = episode(
        &mut env,
        &mut policy,
        &mut channel,
        SessionSettings::default()
            .with_n_att(3)
            .with_wl0(0.5)
            .with_max_items(None),
        0.1,
        1,
        &mut [&mut collector],
    );
    let ev = &report.events;
    assert_eq!(ev.len(), 7);
    assert_eq!(collector.events, report.events);

    let arms: Vec<usize> = ev.iter().map(|e| e.step.arm.0).collect();
    assert_eq!(arms, [0, 1, 1, 0, 2, 2, 1]);
    let items: Vec<usize> = ev.iter().map(|e| e.step.item_index).collect();
    assert_eq!(items, [0, 0, 0, 1, 2, 2, 2]);
    let ts: Vec<u64> = ev.iter().map(|e| e.step.t).collect();
    assert_eq!(ts, [1, 2, 3, 4, 5, 6, 7]);
    assert!(matches!(ev[1].step.decision, StepDecision::Query { .. }));
    assert_eq!(
        ev[2].step.decision,
        StepDecision::FollowExpert { arm: ArmId(1) }
    );
    assert!(
        ev[2].step.diagnostics.is_none(),
        "policy not consulted after a query"
    );
    let wl: Vec<f64> = ev.iter().map(|e| e.step.wl_t).collect();
    for (w, expect) in wl.iter().zip([0.5, 0.6, 0.6, 0.6, 0.6, 0.6, 0.6]) {
        assert!((w - expect).abs() < 1e-12, "{wl:?}");
    }
    assert_eq!(channel.asked, 1);

    // The policy observed every attempt, including the expert's.
    let fb: Vec<(u64, usize, f64, bool)> = policy
        .feedback
        .iter()
        .map(|(t, a, r, e)| (*t, a.0, *r, *e))
        .collect();
    assert_eq!(
        fb,
        [
            (1, 0, 0.0, false),
            (2, 1, 0.0, true),
            (3, 1, 1.0, true),
            (4, 0, 1.0, false),
            (5, 2, 0.0, false),
            (6, 2, 0.0, false),
            (7, 1, 0.0, false),
        ]
    );

    let m = &report.metrics;
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
    assert!(close(m.r_task_avg, 3.4 / 7.0), "{m:?}");
    assert!(close(m.delta_wl, 0.1));
    assert!(close(m.m_wt(0.7), 0.31), "{}", m.m_wt(0.7));
    assert!(close(m.t_conv, 7.0 / 3.0));
    assert!(close(m.f_q, 1.0 / 3.0));
    assert!(close(m.f_fail_food, 1.0 / 3.0));
    assert!(close(m.f_auto_food, 1.0 / 3.0));
    assert_eq!((m.n_success, m.n_q, m.n_items, m.n_steps), (2, 1, 3, 7));
}

#[test]
fn expert_action_is_repeated_until_success() {
    // The expert's arm B fails four times, then succeeds: five attempts, one query.
    let mut env = TableEnv::new(actions(), vec![("kiwi", vec![0.0, 0.5, 0.0])])
        .unwrap()
        .with_outcomes(vec![false, false, false, false, true]);
    let mut policy = ScriptedPolicy::new(3, 3, vec![query(2), act(0)]);
    let mut channel = PerfectExpert::default();
    let r = episode(
        &mut env,
        &mut policy,
        &mut channel,
        SessionSettings::default(),
        0.1,
        0,
        &mut [],
    );
    assert_eq!(r.events.len(), 5);
    assert!(r.events.iter().all(|e| e.step.arm == ArmId(1)));
    assert_eq!(channel.asked, 1);
    assert_eq!(r.metrics.n_q, 1);
    assert!(
        r.events[1..]
            .iter()
            .all(|e| matches!(e.step.decision, StepDecision::FollowExpert { .. }))
    );
}

#[test]
fn item_ends_after_n_att_attempts() {
    let mut env = TableEnv::new(
        actions(),
        vec![("tofu", vec![0.0; 3]), ("egg", vec![1.0; 3])],
    )
    .unwrap();
    let mut policy = ScriptedPolicy::new(3, 4, vec![act(0)]);
    let mut channel = PerfectExpert::default();
    for n_att in [1, 4, 10] {
        let r = episode(
            &mut env,
            &mut policy,
            &mut channel,
            SessionSettings::default().with_n_att(n_att),
            0.1,
            3,
            &mut [],
        );
        let tofu = r.events.iter().filter(|e| e.step.item_index == 0).count();
        assert_eq!(tofu as u32, n_att);
        assert_eq!(r.metrics.n_items, 2);
        assert_eq!(r.metrics.f_fail_food, 0.5);
        // Never queried: the workload never moved.
        assert!(r.events.iter().all(|e| e.step.wl_t == 0.5));
        assert_eq!(r.metrics.delta_wl, 0.0);
    }
}

/// A person who always says "I don't know".
struct Decliner(usize);
impl QueryChannel for Decliner {
    fn name(&self) -> &str {
        "decliner"
    }
    fn ask(&mut self, _q: &Query) -> hil_core::Result<Response> {
        self.0 += 1;
        Ok(Response::without_action(Answer::Declined))
    }
}

#[test]
fn declined_query_falls_back_and_still_costs_workload() {
    let mut env = TableEnv::new(actions(), vec![("pear", vec![0.0, 0.0, 0.0])]).unwrap();
    let mut policy = ScriptedPolicy::new(3, 3, vec![query(2), act(1), query(0)]);
    let mut channel = Decliner(0);
    let r = episode(
        &mut env,
        &mut policy,
        &mut channel,
        SessionSettings::default().with_n_att(3),
        0.2,
        0,
        &mut [],
    );
    let arms: Vec<usize> = r.events.iter().map(|e| e.step.arm.0).collect();
    assert_eq!(
        arms,
        [2, 1, 0],
        "fallback arms are executed, the policy is asked again"
    );
    let wl: Vec<f64> = r.events.iter().map(|e| e.step.wl_t).collect();
    assert!(
        (wl[0] - 0.7).abs() < 1e-12 && (wl[1] - 0.7).abs() < 1e-12 && (wl[2] - 0.9).abs() < 1e-12,
        "{wl:?}"
    );
    assert_eq!(r.metrics.n_q, 2);
    assert_eq!(channel.0, 2);
}

#[test]
fn seeded_episodes_replay_exactly() {
    let run = |seed| {
        let mut env = TableEnv::new(
            actions(),
            vec![("a", vec![0.3, 0.5, 0.7]), ("b", vec![0.6, 0.2, 0.4])],
        )
        .unwrap();
        let mut policy = ScriptedPolicy::new(3, 4, vec![act(0), act(1), query(2), act(2)]);
        let mut channel = PerfectExpert::default();
        episode(
            &mut env,
            &mut policy,
            &mut channel,
            SessionSettings::default(),
            0.1,
            seed,
            &mut [],
        )
        .events
    };
    assert_eq!(run(5), run(5));
}

#[test]
fn shape_mismatch_is_an_error() {
    let mut env = TableEnv::new(actions(), vec![("a", vec![0.3, 0.5, 0.7])]).unwrap();
    let mut policy = ScriptedPolicy::new(3, 99, vec![act(0)]);
    let mut channel = PerfectExpert::default();
    let mut s = Session::new(
        SessionSettings::default(),
        &mut env,
        &mut policy,
        &mut channel,
        Arc::new(CountingWorkload::new(0.1)),
    );
    let e = s.run_episode(0, &mut []).unwrap_err().to_string();
    assert!(e.contains("d = 99") && e.contains("d = 3"), "{e}");
}

#[test]
fn fixtures_pass_their_conformance_suites() {
    use hil_conformance::*;
    let r = check_environment(
        &|| {
            Ok(Box::new(TableEnv::new(
                actions(),
                vec![("a", vec![0.3, 0.5, 0.7]), ("b", vec![0.6, 0.2, 0.4])],
            )?))
        },
        4,
    )
    .unwrap();
    assert!(r.passed.contains(&Check::Replayable));
    let r = check_policy(&|| {
        Ok(Box::new(ScriptedPolicy::new(
            3,
            4,
            vec![act(0), query(1), act(2)],
        )))
    })
    .unwrap();
    assert!(r.passed.contains(&Check::Checkpoint), "{r:?}");
    check_workload_model(&CountingWorkload::new(0.05)).unwrap();
    check_query_channel(&mut PerfectExpert::default(), 20).unwrap();
}

#[test]
fn conformance_catches_a_broken_environment() {
    use hil_conformance::check_environment;
    /// Replays differently on every reset: not seeded.
    struct Unseeded(TableEnv, u64);
    impl hil_core::Environment for Unseeded {
        fn name(&self) -> &str {
            "unseeded"
        }
        fn action_space(&self) -> &ActionSpace {
            self.0.action_space()
        }
        fn context_dim(&self) -> usize {
            self.0.context_dim()
        }
        fn reset(&mut self, _seed: u64) -> hil_core::Result<()> {
            self.1 += 1;
            self.0.reset(self.1)
        }
        fn next_item(&mut self) -> hil_core::Result<Option<hil_core::Item>> {
            self.0.next_item()
        }
        fn observe(&mut self) -> hil_core::Result<hil_core::Context> {
            self.0.observe()
        }
        fn execute(&mut self, arm: ArmId) -> hil_core::Result<hil_core::Outcome> {
            self.0.execute(arm)
        }
        fn current_item(&self) -> Option<&hil_core::Item> {
            self.0.current_item()
        }
    }
    let err = check_environment(
        &|| {
            Ok(Box::new(Unseeded(
                TableEnv::new(actions(), vec![("a", vec![0.5; 3])])?,
                0,
            )))
        },
        3,
    )
    .unwrap_err();
    assert_eq!(err.check, hil_conformance::Check::Replayable);
}

/// A model whose workload decays: each query adds 0.3, forgotten 2 steps
/// later; 0.1 below WL_0 without recent queries.
struct Decaying;
impl hil_core::WorkloadModel for Decaying {
    fn name(&self) -> &str {
        "decaying"
    }
    fn predict(&self, input: &hil_core::WorkloadInput<'_>) -> hil_core::Result<f64> {
        Ok(input.wl0 - 0.1 + 0.3 * input.history.recent(input.t, 2).count() as f64)
    }
}

#[test]
fn workload_is_the_models_wl_t_at_every_step_and_scored_at_the_last() {
    // The paper's WL_T = f(WL_0, Q_T) at the last step: a model that decays
    // between queries decays in the trace and in ΔWL, not only at queries.
    let run = |script: Vec<Choice>, n_att: u32| {
        let mut env = TableEnv::new(actions(), vec![("pear", vec![0.0, 0.0, 0.0])]).unwrap();
        let mut policy = ScriptedPolicy::new(3, 3, script);
        Session::new(
            SessionSettings::default().with_n_att(n_att),
            &mut env,
            &mut policy,
            &mut Decliner(0),
            Arc::new(Decaying),
        )
        .run_episode(0, &mut [])
        .unwrap()
    };
    let r = run(vec![query(2), act(1), act(1), act(1)], 4);
    let wl: Vec<f64> = r.events.iter().map(|e| e.step.wl_t).collect();
    let expect = [0.7, 0.7, 0.4, 0.4];
    assert!(
        wl.iter().zip(expect).all(|(a, b)| (a - b).abs() < 1e-12),
        "{wl:?}"
    );
    let m = &r.metrics;
    assert_eq!((m.t_final, m.n_q, m.queries.len()), (4, 1, 1));
    assert!((m.wl_final - 0.4).abs() < 1e-12 && (m.delta_wl + 0.1).abs() < 1e-12);
    // Rescoring under another model changes the workload figures only.
    let other = m.rescored(&CountingWorkload::new(0.2)).unwrap();
    assert!((other.delta_wl - 0.2).abs() < 1e-12);
    assert_eq!(other.scoring_model, "counting");
    assert_eq!(
        (other.r_task_avg, other.f_q, other.n_q),
        (m.r_task_avg, m.f_q, m.n_q)
    );
    // A policy that never asks is scored at f(WL_0, ∅), not at WL_0.
    let r = run(vec![act(1)], 2);
    assert!((r.metrics.delta_wl + 0.1).abs() < 1e-12, "{:?}", r.metrics);
}

#[test]
fn explicit_component_seeds_reach_each_component() {
    // The environment replays by its own seed whatever the episode's label.
    let run = |label: u64, env_seed: u64| {
        let mut env = TableEnv::new(
            actions(),
            vec![("a", vec![0.3, 0.5, 0.7]), ("b", vec![0.6, 0.2, 0.4])],
        )
        .unwrap();
        let mut policy = ScriptedPolicy::new(3, 4, vec![act(0), act(1), act(2)]);
        let mut channel = PerfectExpert::default();
        let seeds = hil_core::session::ComponentSeeds {
            environment: env_seed,
            policy: 1,
            channel: 2,
        };
        let r = Session::new(
            SessionSettings::default(),
            &mut env,
            &mut policy,
            &mut channel,
            Arc::new(CountingWorkload::new(0.1)),
        )
        .run_episode_with_seeds(label, seeds, &mut [])
        .unwrap();
        assert_eq!(r.seed, label);
        r.events
            .iter()
            .map(|e| (e.step.context.clone(), e.outcome.success))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(1, 42), run(2, 42));
    assert_ne!(run(1, 42), run(1, 43));
}
