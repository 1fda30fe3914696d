//! The user study over many seeds, as a library: each seed's run is the
//! one a single run with that seed gives, whatever the thread count, and
//! the figures over seeds are the mean ± standard error of each seed's.

use std::path::Path;

use hil_experiments::user_study::{UserStudyConfig, UserStudyOverSeeds};
use hil_jobs::Runner;
use hil_stats::Stat;

use crate::study::food_replay_study;

/// Two methods, one tuned, on the bundled synthetic food dataset.
fn study() -> UserStudyConfig {
    let methods = r#"
        [validation]
        plates = 2
        [[methods]]
        label = "LinUCB"
        policy = { type = "linucb", alpha = 0.5, lambda = 1.0, pretrain = true }
        [[methods]]
        label = "LinUCB-QG"
        policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, w = 1.0, pretrain = true }
        tune = { w = [0.5, 8.0] }
        "#;
    UserStudyConfig::parse(
        &food_replay_study(1, r#""banana", "carrot""#, methods),
        Path::new("study.toml"),
    )
    .unwrap()
}

#[test]
fn every_seed_is_its_own_single_run_at_any_thread_count() {
    let cfg = study();
    let seeds = [11, 12, 13];
    let base = Path::new(".");
    let singles: Vec<_> = seeds
        .iter()
        .map(|&s| cfg.run_on_seed(base, s, |_| {}).unwrap())
        .collect();
    // `run_on_seed` is `run` on a config with that seed.
    let mut at_12 = study();
    at_12.seed = 12;
    assert_eq!(at_12.run(base, |_| {}).unwrap(), singles[1]);

    let finished = std::sync::Mutex::new(Vec::new());
    let over = cfg
        .run_over_seeds(base, &seeds, &Runner::new(2).unwrap(), &|s| {
            finished.lock().unwrap().push(s)
        })
        .unwrap();
    assert_eq!(
        over,
        UserStudyOverSeeds::of(seeds.to_vec(), &singles).unwrap()
    );
    let mut finished = finished.into_inner().unwrap();
    finished.sort();
    assert_eq!(finished, seeds);
    let serial = cfg
        .run_over_seeds(base, &seeds, &Runner::new(1).unwrap(), &|_| {})
        .unwrap();
    assert_eq!(serial, over);

    assert_eq!(over.seeds, seeds);
    assert_eq!(over.protocol.seed, 11);
    assert_eq!(over.selections.len(), 3);
    // Each figure is the mean ± SE over seeds of each seed's mean per plate.
    let r: Vec<f64> = singles.iter().map(|s| s.methods[1].r_task_avg).collect();
    assert_eq!(over.methods[1].method, "LinUCB-QG");
    assert_eq!(over.methods[1].r_task_avg, Stat::of(&r));
    // The tuned method's choice per seed, in seed order.
    let chosen = over.chosen();
    assert_eq!(chosen.len(), 1);
    assert_eq!(
        (chosen[0].method.as_str(), chosen[0].parameter.as_str()),
        ("LinUCB-QG", "w")
    );
    let per_seed: Vec<f64> = singles.iter().map(|s| s.selections[0].chosen).collect();
    assert_eq!(chosen[0].values, per_seed);
    assert_eq!(chosen[0].mean, Stat::of(&per_seed));
}

#[test]
fn a_failing_seed_fails_the_run_and_no_seeds_is_an_error() {
    let mut cfg = study();
    // A dataset directory that does not exist: every seed's build fails.
    cfg.environment = UserStudyConfig::parse(
        "[environment]\ntype = \"food_replay\"\ndataset = \"no/such/dir\"\nfoods = [\"banana\"]\n",
        Path::new("bad.toml"),
    )
    .unwrap()
    .environment;
    let runner = Runner::new(2).unwrap();
    let err = cfg
        .run_over_seeds(Path::new("."), &[1, 2], &runner, &|_| {})
        .unwrap_err();
    assert!(err.to_string().contains("no/such/dir"), "{err}");
    let err = study()
        .run_over_seeds(Path::new("."), &[], &runner, &|_| {})
        .unwrap_err();
    assert!(err.to_string().contains("seed"), "{err}");
}

#[test]
fn method_differences_are_paired_seed_by_seed_and_read_against_the_papers_sign() {
    let cfg = study();
    let seeds = [21, 22, 23, 24];
    let singles: Vec<_> = seeds
        .iter()
        .map(|&s| cfg.run_on_seed(Path::new("."), s, |_| {}).unwrap())
        .collect();
    let over = UserStudyOverSeeds::of(seeds.to_vec(), &singles).unwrap();
    assert_eq!(over.differences.len(), 1);
    let d = &over.differences[0];
    // The paper's LinUCB-QG fed more than its LinUCB, so it comes first.
    assert_eq!(
        (d.method.as_str(), d.baseline.as_str()),
        ("LinUCB-QG", "LinUCB")
    );
    let per_seed: Vec<f64> = singles
        .iter()
        .map(|s| s.methods[1].r_task_avg - s.methods[0].r_task_avg)
        .collect();
    // Paired: the standard error is the one of each seed's difference, not
    // the two methods' errors combined as if independent.
    assert_eq!(d.r_task_avg, Stat::of(&per_seed));
    let paper = d.paper.unwrap();
    assert!(paper > 0.0, "{paper}");
    let expected =
        hil_experiments::claims::Verdict::of_difference(d.r_task_avg.mean, d.r_task_avg.se, true)
            .word();
    assert_eq!(d.verdict, Some(expected));
    // One seed leaves the error, and so the verdict, undefined.
    let one = UserStudyOverSeeds::of(vec![21], &singles[..1]).unwrap();
    assert_eq!(one.differences[0].verdict, None);
}
