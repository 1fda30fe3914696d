//! DatasetReplayEnv conformance, dataset round trips and loader errors.

use std::path::PathBuf;
use std::sync::Arc;

use hil_conformance::check_environment;
use hil_core::{ArmId, Environment};
use hil_envs::dataset::FoodDataset;
use hil_envs::generate::SyntheticFoods;
use hil_envs::{DatasetReplayEnv, FoodSplit, OutcomeMode};

fn small() -> Arc<FoodDataset> {
    Arc::new(SyntheticFoods::small().generate().unwrap().dataset)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-envs-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn replay_env_passes_the_conformance_suite() {
    let ds = small();
    let foods = vec!["banana".to_string(), "carrot".to_string()];
    check_environment(
        &|| Ok(Box::new(DatasetReplayEnv::new(ds.clone(), &foods, 5)?)),
        10,
    )
    .unwrap();
}

#[test]
fn bundled_replay_env_passes_the_conformance_suite() {
    let ds = hil_envs::bundled_dataset().unwrap();
    assert_eq!(ds.context_dim, 2048);
    let foods = vec!["cantaloupe".to_string(), "grape".to_string()];
    check_environment(
        &|| Ok(Box::new(DatasetReplayEnv::new(ds.clone(), &foods, 3)?)),
        4,
    )
    .unwrap();
}

#[test]
fn best_action_is_argmax_and_success_frequency_matches_probability() {
    let ds = small();
    let mut env = DatasetReplayEnv::new(ds.clone(), &["apple".into()], 400).unwrap();
    env.reset(5).unwrap();
    let (mut succ, mut prob) = (0.0, 0.0);
    let mut n = 0.0;
    while env.next_item().unwrap().is_some() {
        let x = env.observe().unwrap();
        let img = &ds.foods[0].images[env.last_image().unwrap()];
        assert_eq!(img.context, x);
        let best = env.best_action().unwrap();
        assert!(img.success.iter().all(|p| *p <= img.success[best.0]));
        let out = env.execute(ArmId(0)).unwrap();
        prob += out.success_probability.unwrap();
        succ += out.reward();
        n += 1.0;
    }
    // 400 Bernoulli draws: the frequency is within 4 standard errors.
    assert!(
        (succ / n - prob / n).abs() < 4.0 * 0.5 / 20.0,
        "{succ} {prob}"
    );
}

#[test]
fn replay_mode_replays_recorded_outcomes() {
    let mut ds = (*small()).clone();
    for f in &mut ds.foods {
        for img in &mut f.images {
            // Record "always fails" except action 1, "always succeeds".
            img.outcomes = Some((0..6).map(|a| vec![a == 1; 3]).collect());
        }
    }
    let ds = Arc::new(ds);
    let mut env = DatasetReplayEnv::new(ds.clone(), &["carrot".into()], 3)
        .unwrap()
        .with_outcomes(OutcomeMode::Replay)
        .unwrap();
    env.reset(0).unwrap();
    env.next_item().unwrap();
    env.observe().unwrap();
    assert!(env.execute(ArmId(1)).unwrap().success);
    env.observe().unwrap();
    assert!(!env.execute(ArmId(3)).unwrap().success);
    // Without recordings, replay is refused up front.
    assert!(
        DatasetReplayEnv::new(small(), &["carrot".into()], 3)
            .unwrap()
            .with_outcomes(OutcomeMode::Replay)
            .is_err()
    );
}

#[test]
fn out_of_order_calls_are_errors() {
    let mut env = DatasetReplayEnv::new(small(), &["kiwi".into()], 1).unwrap();
    assert!(env.observe().is_err());
    env.reset(0).unwrap();
    env.next_item().unwrap();
    assert!(env.execute(ArmId(0)).is_err()); // before observe
    env.observe().unwrap();
    assert!(env.execute(ArmId(6)).is_err());
}

#[test]
fn save_then_load_round_trips_with_outcomes() {
    let mut ds = (*small()).clone();
    ds.foods.truncate(3);
    ds.foods[1].images[0].context = hil_core::Context::new(vec![0.5; 224]).unwrap();
    for img in &mut ds.foods[2].images {
        img.outcomes = Some((0..6).map(|a| vec![a % 2 == 0, true]).collect());
    }
    let dir = tmp("roundtrip");
    let manifest = ds.save(&dir).unwrap();
    let back = FoodDataset::load(&manifest).unwrap();
    assert_eq!(back, ds);
    assert_eq!(FoodDataset::load(&dir).unwrap(), ds);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn splits_reject_unknown_empty_and_shared_foods() {
    let ds = small();
    FoodSplit::paper().validate(&ds).unwrap();
    let mut s = FoodSplit::paper();
    s.test.push("durian".into());
    let e = s.validate(&ds).unwrap_err().to_string();
    assert!(
        e.contains("split.test") && e.contains("durian") && e.contains("unknown"),
        "{e}"
    );
    let mut s = FoodSplit::paper();
    s.validation.clear();
    assert!(
        s.validate(&ds)
            .unwrap_err()
            .to_string()
            .contains("split.validation")
    );
    let mut s = FoodSplit::paper();
    s.test.push("apple".into());
    let e = s.validate(&ds).unwrap_err().to_string();
    assert!(e.contains("apple") && e.contains("split.pretrain"), "{e}");
    // Twice in one list is said as such, not as "also in" that list.
    let mut s = FoodSplit::paper();
    let first = s.test[0].clone();
    s.test.push(first);
    let e = s.validate(&ds).unwrap_err().to_string();
    assert!(e.contains("named twice in `split.test`"), "{e}");
}

#[test]
fn food_replay_config_builds_and_offers_pretraining_data() {
    let text = r#"
type = "food_replay"
foods = ["banana", "carrot"]
pretrain_foods = ["apple", "kiwi"]
items_per_episode = 4
"#;
    let cfg: Box<dyn hil_config::EnvironmentConfig> = toml::from_str(text).unwrap();
    let ctx = hil_config::BuildContext::new(".", 0);
    let env = cfg.build(&ctx).unwrap();
    assert_eq!(env.context_dim(), 2048);
    let pre = cfg.pretraining(&ctx).unwrap().unwrap();
    assert_eq!(pre.len(), 2 * 30 * 6);
    let bad: Box<dyn hil_config::EnvironmentConfig> = toml::from_str(
        "type = \"food_replay\"\nfoods = [\"banana\"]\npretrain_foods = [\"banana\"]\n",
    )
    .unwrap();
    let e = bad.build(&ctx).err().unwrap().to_string();
    assert!(e.contains("banana") && e.contains("pretrain_foods"), "{e}");
    assert!(
        toml::from_str::<Box<dyn hil_config::EnvironmentConfig>>(
            "type = \"food_replay\"\nfoods = [\"banana\"]\nfood = 1\n"
        )
        .is_err()
    );
}
