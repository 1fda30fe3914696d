//! The "gap monotonicity" property suite for LinUCB-QG and its estimator.

use crate::estimator::reference::NaiveArms;
use crate::{
    EstimatorOptions, LinUcbQg, LinUcbQgParams, LinearArms, RepresentationChoice, query_gap,
};
use hil_conformance::strategies::context;
use hil_core::WorkloadInput;
use hil_core::{
    ArmId, Choice, Context, DecisionInput, LabelledObservation, Policy, QueryHistory, QueryKind,
    Result, WorkloadForecast, WorkloadModel,
};
use proptest::prelude::*;

const DIM: usize = 4;
const ARMS: usize = 3;

fn observations(max: usize) -> impl Strategy<Value = Vec<LabelledObservation>> {
    proptest::collection::vec((context(DIM, 1.0), 0..ARMS, 0.0f64..=1.0), 0..=max).prop_map(|v| {
        v.into_iter()
            .map(|(context, arm, reward)| LabelledObservation {
                context,
                arm: ArmId(arm),
                reward,
            })
            .collect()
    })
}

fn representation() -> impl Strategy<Value = RepresentationChoice> {
    prop_oneof![
        Just(RepresentationChoice::Auto),
        Just(RepresentationChoice::Kernel),
        Just(RepresentationChoice::Dense),
    ]
}

fn fitted(data: &[LabelledObservation], r: RepresentationChoice, lambda: f64) -> LinearArms {
    let opts = EstimatorOptions {
        representation: r,
        crossover: 1.0,
    };
    let mut arms = LinearArms::with_options(ARMS, DIM, lambda, opts).unwrap();
    arms.pretrain(data).unwrap();
    arms
}

fn gap(arms: &mut LinearArms, x: &Context, alpha: f64) -> f64 {
    query_gap(&arms.scores(x).unwrap(), alpha).unwrap().gap
}

/// WL_t is a fixed number, whatever the history.
struct Fixed(f64);

impl WorkloadModel for Fixed {
    fn name(&self) -> &str {
        "fixed"
    }
    fn predict(&self, _: &WorkloadInput<'_>) -> Result<f64> {
        Ok(self.0)
    }
}

fn queries(p: &mut LinUcbQg, x: &Context, wl: f64) -> bool {
    let model = Fixed(wl);
    let h = QueryHistory::new();
    let input = DecisionInput::new(x, 1, WorkloadForecast::new(Some(&model), 0.5, &h, 1));
    matches!(p.decide(&input).unwrap().choice, Choice::Query { .. })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn gap_is_non_decreasing_in_alpha(
        data in observations(12),
        x in context(DIM, 1.0),
        r in representation(),
        a1 in 0.0f64..3.0,
        da in 0.0f64..3.0,
    ) {
        let mut arms = fitted(&data, r, 1.0);
        let g1 = gap(&mut arms, &x, a1);
        let g2 = gap(&mut arms, &x, a1 + da);
        prop_assert!(g2 >= g1 - 1e-12, "G({a1}) = {g1} > G({}) = {g2}", a1 + da);
    }

    #[test]
    fn bonuses_never_grow_after_an_update(
        data in observations(10),
        probe in context(DIM, 1.0),
        xu in context(DIM, 1.0),
        arm in 0..ARMS,
        reward in 0.0f64..=1.0,
        r in representation(),
        lambda in 0.05f64..5.0,
    ) {
        let mut arms = fitted(&data, r, lambda);
        let before = arms.scores(&probe).unwrap();
        arms.update(&xu, ArmId(arm), reward).unwrap();
        let after = arms.scores(&probe).unwrap();
        for (b, a) in before.iter().zip(&after) {
            prop_assert!(a.bonus <= b.bonus * (1.0 + 1e-10) + 1e-12, "{b:?} -> {a:?}");
        }
    }

    #[test]
    fn confirming_observations_never_increase_the_gap(
        data in observations(10),
        probe in context(DIM, 1.0),
        updates in proptest::collection::vec((context(DIM, 1.0), 0..ARMS), 1..5),
        r in representation(),
        alpha in 0.0f64..2.0,
    ) {
        let mut arms = fitted(&data, r, 1.0);
        let mut g = gap(&mut arms, &probe, alpha);
        for (x, arm) in updates {
            // The reward equals the arm's current estimate: θ does not move,
            // only the uncertainty shrinks.
            let est = arms.estimate(ArmId(arm), &x).unwrap().estimate;
            arms.update(&x, ArmId(arm), est).unwrap();
            let g2 = gap(&mut arms, &probe, alpha);
            prop_assert!(g2 <= g + 1e-9 * (1.0 + g.abs()), "G rose from {g} to {g2}");
            g = g2;
        }
    }

    #[test]
    fn qg_decision_is_monotone_in_the_threshold(
        data in observations(10),
        x in context(DIM, 1.0),
        alpha in 0.0f64..2.0,
        w in 0.0f64..2.0,
        wl in 0.0f64..=1.0,
        w2 in 0.0f64..2.0,
        wl2 in 0.0f64..=1.0,
    ) {
        let arms = fitted(&data, RepresentationChoice::Auto, 1.0);
        let k = QueryKind::default();
        let mut p1 = LinUcbQg::new(LinUcbQgParams::new(alpha, w, k).unwrap(), arms.clone());
        let mut p2 = LinUcbQg::new(LinUcbQgParams::new(alpha, w2, k).unwrap(), arms);
        if queries(&mut p1, &x, wl) && w2 * wl2 <= w * wl {
            prop_assert!(queries(&mut p2, &x, wl2));
        }
    }

    #[test]
    fn kernel_dense_and_naive_agree(
        data in observations(14),
        online in observations(6),
        probe in context(DIM, 1.0),
        lambda in 0.05f64..5.0,
    ) {
        let mut kernel = fitted(&data, RepresentationChoice::Kernel, lambda);
        let mut dense = fitted(&data, RepresentationChoice::Dense, lambda);
        let mut naive = NaiveArms::new(ARMS, DIM, lambda);
        for o in data.iter().chain(&online) {
            naive.push(o.arm.0, &o.context, o.reward);
        }
        for o in &online {
            kernel.update(&o.context, o.arm, o.reward).unwrap();
            dense.update(&o.context, o.arm, o.reward).unwrap();
        }
        let k = kernel.scores(&probe).unwrap();
        let d = dense.scores(&probe).unwrap();
        for a in 0..ARMS {
            let n = naive.estimate(a, &probe).unwrap();
            for (what, got, want) in [
                ("kernel estimate", k[a].estimate, n.estimate),
                ("dense estimate", d[a].estimate, n.estimate),
                ("kernel bonus", k[a].bonus, n.bonus),
                ("dense bonus", d[a].bonus, n.bonus),
            ] {
                let scale = got.abs().max(want.abs()).max(1e-3);
                prop_assert!((got - want).abs() <= 1e-8 * scale, "{what}: {got} vs {want}");
            }
        }
    }
}
