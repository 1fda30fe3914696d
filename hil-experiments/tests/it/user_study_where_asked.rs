//! Where each method asks: the per-food and per-attempt breakdown of the
//! queries agrees with the per-plate counts, on a cheap environment.

use std::path::Path;

use hil_experiments::user_study::UserStudyConfig;

use crate::study::food_replay_study;

#[test]
fn queries_by_food_and_by_attempt_add_up_to_the_plate_count() {
    let cfg = UserStudyConfig::parse(
        &food_replay_study(2, r#""banana", "carrot""#, ""),
        Path::new("study.toml"),
    )
    .unwrap();
    let result = cfg.run(Path::new("."), |_| {}).unwrap();
    let mut asked_somewhere = false;
    for p in &result.plates {
        assert_eq!(p.n_q_by_food.values().sum::<usize>(), p.n_q, "{p:?}");
        assert_eq!(p.n_q_by_attempt.iter().sum::<usize>(), p.n_q, "{p:?}");
        assert_eq!(p.n_q_by_attempt.len(), cfg.session.n_att as usize);
        // Every food the plate met is listed, asked at or not.
        assert!(
            p.n_q_by_food
                .keys()
                .all(|f| result.protocol.foods.contains(f))
        );
        asked_somewhere |= p.n_q > 0;
    }
    assert!(asked_somewhere, "AlwaysQuery asks on every plate");
    for m in &result.methods {
        let by_food: f64 = m.n_q_by_food.values().sum();
        let by_attempt: f64 = m.n_q_by_attempt.iter().sum();
        assert!((by_food - m.n_q_per_plate).abs() < 1e-9, "{m:?}");
        assert!((by_attempt - m.n_q_per_plate).abs() < 1e-9, "{m:?}");
    }
    // AlwaysQuery asks at the first attempt of every item and nowhere else
    // (it then follows the answer).
    let aq = result
        .methods
        .iter()
        .find(|m| m.method == "AlwaysQuery")
        .unwrap();
    assert!(aq.n_q_by_attempt[0] > 0.0);
    assert!(aq.n_q_by_attempt[1..].iter().all(|&q| q == 0.0), "{aq:?}");
}
