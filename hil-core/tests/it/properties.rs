//! Session-loop and metric invariants over random episodes.

use std::sync::Arc;

use hil_core::channel::PerfectExpert;

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_conformance::strategies;
use hil_core::{ActionSpace, ArmId, Choice, QueryKind, Session, SessionSettings, StepDecision};
use proptest::prelude::*;

fn choice() -> impl Strategy<Value = Choice> {
    prop_oneof![
        (0..3usize).prop_map(|a| Choice::Act { arm: ArmId(a) }),
        (0..3usize, strategies::query_kind()).prop_map(|(a, kind)| Choice::Query {
            kind,
            fallback: ArmId(a)
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn episode_invariants(
        probs in proptest::collection::vec(proptest::collection::vec(0.0f64..=1.0, 3), 1..6),
        script in proptest::collection::vec(choice(), 1..30),
        n_att in 1u32..6,
        seed in any::<u64>(),
        inc in 0.0f64..0.3,
    ) {
        let items = probs.iter().enumerate().map(|(i, p)| (["a", "b", "c", "d", "e"][i], p.clone())).collect();
        let mut env = TableEnv::new(ActionSpace::new(["A", "B", "C"]).unwrap(), items).unwrap();
        let dim = hil_core::Environment::context_dim(&env);
        let mut policy = ScriptedPolicy::new(3, dim, script);
        let mut channel = PerfectExpert::default();
        let mut s = Session::new(SessionSettings::default().with_n_att(n_att).with_wl0(0.5).with_max_items(None), &mut env, &mut policy, &mut channel, Arc::new(CountingWorkload::new(inc)));
        let r = s.run_episode(seed, &mut []).unwrap();
        let m = &r.metrics;
        prop_assert_eq!(m.n_items, probs.len());
        prop_assert_eq!(m.n_steps, r.events.len());
        prop_assert!(m.t_conv >= 1.0 && m.t_conv <= f64::from(n_att));
        // Every item is exactly one of: failed, acquired alone, acquired after a query.
        prop_assert!(m.f_fail_food + m.f_auto_food <= 1.0 + 1e-12);
        prop_assert!(m.f_auto_food + m.f_q <= 1.0 + 1e-12);
        prop_assert!((0.0..=1.0).contains(&m.r_task_avg));
        // One query costs `inc` (clamped to the scale): workload moves only at queries.
        let expect = (0.5 + inc * m.n_q as f64).clamp(0.0, 1.0);
        prop_assert!((m.wl_final - expect).abs() < 1e-9);
        let mut prev_wl = 0.5;
        let mut expert: Option<(usize, ArmId)> = None;
        for e in &r.events {
            let st = &e.step;
            if !st.decision.is_query() {
                prop_assert_eq!(st.wl_t, prev_wl);
            }
            prev_wl = st.wl_t;
            // After a query answered at an item, that item follows the expert.
            if let Some((item, arm)) = expert {
                if item == st.item_index {
                    prop_assert_eq!(st.decision, StepDecision::FollowExpert { arm });
                }
            }
            if st.decision.is_query() {
                expert = st.response.as_ref().and_then(|r| r.expert_arm).map(|a| (st.item_index, a));
            }
            prop_assert!(st.attempt < n_att);
        }
        // The M_wt identity.
        let w = 0.7;
        prop_assert!((m.m_wt(w) - (w * m.r_task_avg - (1.0 - w) * m.delta_wl)).abs() < 1e-12);
    }

    #[test]
    fn query_history_strategy_is_sorted(h in strategies::query_history(30, 100)) {
        let ts: Vec<u64> = h.records().iter().map(|r| r.t).collect();
        prop_assert!(ts.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn spd_strategy_is_positive_definite(a in strategies::spd_matrix(4, 1e-3), v in proptest::collection::vec(-1.0f64..1.0, 4)) {
        let n = 4;
        let mut q = 0.0;
        for i in 0..n { for j in 0..n { q += v[i] * a[i * n + j] * v[j]; } }
        let vv: f64 = v.iter().map(|x| x * x).sum();
        prop_assert!(q >= 1e-3 * vv - 1e-12);
        for i in 0..n { for j in 0..n { prop_assert_eq!(a[i * n + j], a[j * n + i]); } }
    }

    #[test]
    fn context_strategy_is_finite(x in strategies::context(16, 5.0)) {
        prop_assert_eq!(x.dim(), 16);
        prop_assert!(x.iter().all(|v| v.is_finite() && v.abs() <= 5.0));
    }
}

#[test]
fn default_query_kind_is_easy_mcq_without_distraction() {
    let k = QueryKind::default();
    assert_eq!(
        serde_json::to_string(&k).unwrap(),
        r#"{"response":"mcq","difficulty":"easy","distraction":"none"}"#
    );
}
