//! The four policies inside the hil-core session loop: query semantics per
//! item, diagnostics, and learning from every executed attempt.

use std::sync::Arc;

use hil_conformance::fixtures::{CountingWorkload, TableEnv};
use hil_core::PerfectExpert;
use hil_core::{
    ActionSpace, ArmId, EpisodeReport, Policy, QueryKind, Session, SessionSettings, StepDecision,
};
use hil_policies::{
    AlwaysQuery, AlwaysQueryParams, LinUcb, LinUcbExpDecay, LinUcbExpDecayParams, LinUcbParams,
    LinUcbQg, LinUcbQgParams, LinearArms,
};

const ARMS: usize = 3;
const DIM: usize = 4; // two item types + two noise features

fn env() -> TableEnv {
    let a = ("apple", vec![0.1, 0.9, 0.3]);
    let b = ("bean", vec![0.8, 0.1, 0.2]);
    let items = (0..10).map(|i| if i % 2 == 0 { a.clone() } else { b.clone() });
    TableEnv::new(ActionSpace::new(["A", "B", "C"]).unwrap(), items.collect()).unwrap()
}

fn run(policy: &mut dyn Policy, seed: u64) -> EpisodeReport {
    let mut env = env();
    let mut channel = PerfectExpert::default();
    let mut s = Session::new(
        SessionSettings::default()
            .with_n_att(4)
            .with_wl0(0.5)
            .with_max_items(None),
        &mut env,
        policy,
        &mut channel,
        Arc::new(CountingWorkload::new(0.05)),
    );
    s.run_episode(seed, &mut []).unwrap()
}

fn arms() -> LinearArms {
    LinearArms::new(ARMS, DIM, 1.0).unwrap()
}

/// After a query, the rest of the item follows the expert.
fn check_follow_expert(r: &EpisodeReport) {
    let mut queried_item = None;
    for e in &r.events {
        match e.step.decision {
            StepDecision::Query { .. } => queried_item = Some(e.step.item_index),
            StepDecision::FollowExpert { .. } => {
                assert_eq!(queried_item, Some(e.step.item_index))
            }
            StepDecision::Act { .. } => assert_ne!(queried_item, Some(e.step.item_index)),
        }
    }
}

#[test]
fn linucb_qg_queries_by_gap_and_learns_from_every_attempt() {
    let k = QueryKind::default();
    let mut p = LinUcbQg::new(LinUcbQgParams::new(1.0, 0.5, k).unwrap(), arms());
    let r = run(&mut p, 3);
    check_follow_expert(&r);
    let mut n_queries = 0;
    for e in &r.events {
        let Some(d) = &e.step.diagnostics else {
            continue;
        };
        let (g, th) = (d.gap.unwrap(), d.threshold.unwrap());
        assert_eq!(d.arms.len(), ARMS);
        assert!((th - 0.5 * d.workload_forecast.unwrap()).abs() < 1e-15);
        assert_eq!(
            e.step.decision.is_query(),
            g > th,
            "G = {g}, threshold {th}"
        );
        n_queries += usize::from(e.step.decision.is_query());
    }
    // Knows nothing at first, so it asks; learns, so it stops asking.
    assert!(r.events[0].step.decision.is_query());
    assert!(n_queries < r.events.len());
    let seen: usize = (0..ARMS)
        .map(|a| p.estimator().n_observations(ArmId(a)).unwrap())
        .sum();
    assert_eq!(seen, r.events.len(), "every executed attempt is observed");

    // A prohibitive workload weight never queries.
    let mut never = LinUcbQg::new(LinUcbQgParams::new(1.0, 1e6, k).unwrap(), arms());
    assert!(
        !run(&mut never, 3)
            .events
            .iter()
            .any(|e| e.step.decision.is_query())
    );
}

#[test]
fn always_query_asks_at_every_item() {
    let params = AlwaysQueryParams::new(0.5, QueryKind::default()).unwrap();
    let mut p = AlwaysQuery::new(params, arms());
    let r = run(&mut p, 1);
    check_follow_expert(&r);
    for e in &r.events {
        assert_eq!(e.step.decision.is_query(), e.step.attempt == 0);
    }
}

#[test]
fn exp_decay_asks_only_on_first_attempts_and_is_seeded() {
    let params = LinUcbExpDecayParams::new(0.5, 0.3, QueryKind::default()).unwrap();
    let mut p = LinUcbExpDecay::new(params, arms());
    let r = run(&mut p, 11);
    check_follow_expert(&r);
    for e in &r.events {
        if e.step.decision.is_query() {
            assert_eq!(e.step.attempt, 0);
        }
        if let Some(d) = &e.step.diagnostics {
            assert_eq!(d.query_probability.is_some(), e.step.attempt == 0);
        }
    }
    let mut q = LinUcbExpDecay::new(params, arms());
    let r2 = run(&mut q, 11);
    assert_eq!(r.events, r2.events);
}

#[test]
fn linucb_never_queries() {
    let mut p = LinUcb::new(LinUcbParams::new(0.5).unwrap(), arms());
    let r = run(&mut p, 5);
    assert!(r.events.iter().all(|e| !e.step.decision.is_query()));
}
