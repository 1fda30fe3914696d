//! Simulated experts: conformance, rates, seeding and configs.

use hil_channels::{ResponseTimeModel, SimulatedExpert, SimulatedExpertConfig};
use hil_config::BuildContext;
use hil_config::QueryChannelConfig;
use hil_config::TaskContext;
use hil_conformance::check_query_channel;
use hil_core::ActionSpace;
use hil_core::channel::PerfectExpert;
use hil_core::{
    Answer, ArmId, Context, HilError, Item, Query, QueryChannel, QueryKind, ResponseType,
};

fn query(t: u64, best: usize, response: ResponseType) -> Query {
    Query::new(
        t,
        Item::new(0, "carrot"),
        QueryKind {
            response,
            ..Default::default()
        },
        hil_envs::feeding::action_space(),
        Context::new(vec![1.0, 0.0]).unwrap(),
    )
    .with_oracle_best(ArmId(best))
}

/// The simulated expert with default parameters: the paper's perfect expert.
fn perfect() -> SimulatedExpert {
    SimulatedExpert::new(SimulatedExpertConfig::default()).unwrap()
}

fn expert(error_rate: f64, decline_rate: f64) -> SimulatedExpert {
    SimulatedExpert::new(SimulatedExpertConfig {
        error_rate,
        decline_rate,
        response_time: Some(ResponseTimeModel {
            median_s: 4.0,
            sigma: 0.5,
        }),
    })
    .unwrap()
}

#[test]
fn perfect_and_imperfect_experts_conform() {
    check_query_channel(&mut PerfectExpert::default(), 36).unwrap();
    check_query_channel(&mut perfect(), 36).unwrap();
    check_query_channel(&mut expert(0.3, 0.2), 36).unwrap();
    check_query_channel(&mut expert(1.0, 0.0), 36).unwrap();
}

#[test]
fn perfect_expert_always_answers_the_best_action() {
    let mut e = perfect();
    for t in 1..50 {
        let best = (t as usize * 7) % 6;
        for rt in ResponseType::ALL {
            let r = e.ask(&query(t, best, rt)).unwrap();
            assert_eq!(r.expert_arm, Some(ArmId(best)));
            assert_eq!(r.response_time_s, None);
            match (rt, &r.answer) {
                (ResponseType::Mcq, Answer::Action { arm }) => assert_eq!(*arm, ArmId(best)),
                (ResponseType::BoundingBox, Answer::BoundingBox { bbox }) => {
                    assert!(0.0 <= bbox.x0 && bbox.x0 < bbox.x1 && bbox.x1 <= 1.0)
                }
                (ResponseType::OpenEnded, Answer::Text { text }) => {
                    assert!(text.contains(hil_envs::feeding::action_space().names()[best].as_str()))
                }
                other => panic!("unexpected answer {other:?}"),
            }
        }
    }
}

#[test]
fn error_and_decline_rates_are_honoured() {
    let mut e = expert(0.3, 0.2);
    e.seed(11);
    let n = 4000;
    let (mut declined, mut wrong, mut answered) = (0, 0, 0);
    let mut times = Vec::new();
    for t in 1..=n {
        let r = e.ask(&query(t, 2, ResponseType::Mcq)).unwrap();
        times.push(r.response_time_s.unwrap());
        match r.answer {
            Answer::Declined => {
                declined += 1;
                assert_eq!(r.expert_arm, None);
            }
            Answer::Action { arm } => {
                answered += 1;
                if arm != ArmId(2) {
                    wrong += 1;
                }
            }
            other => panic!("unexpected {other:?}"),
        }
    }
    // Seeded, so exact counts are reproducible; these bounds are ±5 standard deviations.
    let decline_frac = declined as f64 / n as f64;
    let wrong_frac = wrong as f64 / answered as f64;
    assert!((decline_frac - 0.2).abs() < 0.035, "{decline_frac}");
    assert!((wrong_frac - 0.3).abs() < 0.04, "{wrong_frac}");
    let median = hil_stats::median(&times);
    assert!((median - 4.0).abs() < 0.3, "median response time {median}");
}

#[test]
fn wrong_answers_are_spread_over_the_other_arms() {
    let mut e = expert(1.0, 0.0);
    let mut seen = [0usize; 6];
    for t in 1..=600 {
        let r = e.ask(&query(t, 3, ResponseType::Mcq)).unwrap();
        seen[r.expert_arm.unwrap().0] += 1;
    }
    assert_eq!(seen[3], 0);
    assert!(
        seen.iter().enumerate().all(|(i, c)| i == 3 || *c > 60),
        "{seen:?}"
    );
}

#[test]
fn seeded_answers_are_reproducible_and_independent_of_skipped_queries() {
    let mut a = expert(0.4, 0.3);
    let mut b = expert(0.4, 0.3);
    a.seed(99);
    b.seed(99);
    let all: Vec<_> = (1..=40)
        .map(|t| a.ask(&query(t, 1, ResponseType::Mcq)).unwrap())
        .collect();
    // b skips every other query (as a resumed session replays them from the
    // record): the answers it does give are unchanged.
    for t in (2..=40).step_by(2) {
        assert_eq!(
            b.ask(&query(t, 1, ResponseType::Mcq)).unwrap(),
            all[t as usize - 1]
        );
    }
    let mut c = expert(0.4, 0.3);
    c.seed(100);
    let other: Vec<_> = (1..=40)
        .map(|t| c.ask(&query(t, 1, ResponseType::Mcq)).unwrap())
        .collect();
    assert_ne!(all, other);
}

#[test]
fn missing_oracle_is_a_clear_error() {
    let mut q = query(1, 0, ResponseType::Mcq);
    q.oracle_best = None;
    assert!(matches!(perfect().ask(&q), Err(HilError::Channel { .. })));
    assert!(matches!(
        PerfectExpert::default().ask(&q),
        Err(HilError::Channel { .. })
    ));
}

#[derive(serde::Deserialize)]
struct Doc {
    channel: Box<dyn QueryChannelConfig>,
}

#[test]
fn config_parses_validates_and_rejects_unknown_fields() {
    let actions = ActionSpace::new(["a", "b"]).unwrap();
    let ctx = TaskContext::new(BuildContext::new(".", 0), actions, 3);
    let ok: Doc = toml::from_str(
        "[channel]\ntype = \"simulated_expert\"\nerror_rate = 0.1\ndecline_rate = 0.05\nresponse_time = { median_s = 3.0, sigma = 0.2 }\n",
    )
    .unwrap();
    check_query_channel(ok.channel.build(&ctx).unwrap().as_mut(), 12).unwrap();

    let bad: Doc =
        toml::from_str("[channel]\ntype = \"simulated_expert\"\nerror_rate = 1.5\n").unwrap();
    let err = bad.channel.build(&ctx).err().unwrap();
    assert!(
        matches!(err, HilError::InvalidParameter { ref name, ref value, .. } if name == "error_rate" && value == "1.5"),
        "{err:?}"
    );

    let bad: Doc = toml::from_str(
        "[channel]\ntype = \"simulated_expert\"\nresponse_time = { median_s = -1.0 }\n",
    )
    .unwrap();
    let err = bad.channel.build(&ctx).err().unwrap();
    assert!(
        matches!(err, HilError::InvalidParameter { ref name, .. } if name.ends_with("median_s")),
        "{err:?}"
    );

    let unknown =
        toml::from_str::<Doc>("[channel]\ntype = \"simulated_expert\"\neror_rate = 0.1\n");
    let err = unknown.err().unwrap().to_string();
    assert!(err.contains("eror_rate"), "{err}");
}
