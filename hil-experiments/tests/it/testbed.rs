//! The simulated-testbed protocol end to end on a small dataset, with the
//! paper's real policies (hil-policies) and hil-core's counting workload
//! model.

use std::sync::Arc;

use hil_conformance::fixtures::CountingWorkload;
use hil_envs::generate::SyntheticFoods;
use hil_envs::{FoodDataset, FoodSplit};
use hil_experiments::results::{Reproduction, Spread, aggregate};
use hil_experiments::testbed::{CrossSetting, Phase, RunKey, RunRecord};
use hil_experiments::{NamedModel, Protocol, ProtocolSettings};

pub fn setup() -> (Arc<FoodDataset>, ProtocolSettings, Vec<NamedModel>) {
    let ds = Arc::new(
        SyntheticFoods {
            dim: 224,
            images_per_setting: 2,
            ..SyntheticFoods::default()
        }
        .generate()
        .unwrap()
        .dataset,
    );
    let mut settings = ProtocolSettings {
        n_policy_seeds: 3,
        many_seeds: 0,
        w_tasks: vec![0.2, 0.9],
        cross: vec![CrossSetting {
            method: "LinUCB-QG".into(),
            decide: "slow".into(),
            score: "fast".into(),
        }],
        grid_variants: Vec::new(),
        ..ProtocolSettings::paper()
    };
    settings.methods[2].tune.insert("c".into(), vec![0.0, 2.0]);
    settings.methods[3]
        .tune
        .insert("w".into(), vec![0.5, 1.5, 3.0]);
    settings.figures.model = "fast".into();
    settings.figures.w_task = 0.9;
    let models = vec![
        NamedModel {
            name: "slow".into(),
            model: Arc::new(CountingWorkload::new(0.05)),
        },
        NamedModel {
            name: "fast".into(),
            model: Arc::new(CountingWorkload::new(0.3)),
        },
    ];
    (ds, settings, models)
}

/// `p`'s records on a runner of `threads` workers.
fn run_all(p: &mut Protocol, threads: usize) -> Vec<RunRecord> {
    p.runner = hil_jobs::Runner::new(threads).unwrap();
    p.run_all(&|_, _| {}).unwrap()
}

#[test]
fn protocol_runs_selects_on_validation_and_is_deterministic() {
    let (ds, settings, models) = setup();
    let mut p = Protocol::new(settings.clone(), ds.clone(), models.clone()).unwrap();
    // What each method needs comes from its config: 2 phases × 3 seeds ×
    // (LinUCB + AQ + 2 c × 3 policy seeds + 3 w × 2 deciding models).
    assert_eq!(p.jobs().unwrap().len(), 2 * 3 * (1 + 1 + 6 + 6));
    let seen = std::sync::atomic::AtomicUsize::new(0);
    let recs = p
        .run_all(&|_, _| {
            seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
    assert_eq!(seen.into_inner(), recs.len());
    let json = |r: &[RunRecord]| serde_json::to_string(r).unwrap();
    assert_eq!(
        json(&run_all(&mut p, 1)),
        json(&run_all(&mut p, 2)),
        "thread count changed results"
    );

    let res = aggregate(&settings, &models, &recs, "test data", 3, Spread::Std).unwrap();
    assert_eq!(res.rows.len(), 2 * 2 * 4);
    for r in &res.rows {
        match r.method.as_str() {
            "AlwaysQuery" => assert_eq!(r.test.f_q.mean, 1.0),
            "LinUCB" => {
                assert_eq!(r.test.f_q.mean, 0.0);
                // No queries: the counting model stays at WL_0.
                assert_eq!(r.test.delta_wl.mean, 0.0);
            }
            _ => assert!(r.selected.is_some()),
        }
        // M_wt is consistent with its parts (means are linear).
        let m = r.w_task * r.test.r_task_avg.mean - (1.0 - r.w_task) * r.test.delta_wl.mean;
        assert!((m - r.test.m_wt.mean).abs() < 1e-12);
    }
    // The chosen value maximises mean validation M_wt.
    for s in &res.selection {
        let best = s
            .candidates
            .iter()
            .map(|c| c.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let chosen = s.candidates.iter().find(|c| c.0 == s.chosen).unwrap().1;
        assert_eq!(chosen, best);
    }
    // Cross row: QG decided with `slow`, w chosen as in the slow row, scored
    // with `fast` through hil-core's rescoring.
    let c = &res.cross[0];
    assert!(res.row("slow", 0.4, "LinUCB-QG").is_none()); // selection still ran
    assert_eq!(c.test.n_runs, 3);
    let decided: Vec<&RunRecord> = recs
        .iter()
        .filter(|r| {
            r.key.phase == Phase::Test
                && r.key.method == 3
                && r.key.decide_model == Some(0)
                && r.key.point.as_ref().map(|p| p.1) == c.selected.as_ref().map(|h| h.value)
        })
        .collect();
    let rescored: f64 = decided
        .iter()
        .map(|r| {
            r.metrics
                .rescored(models[1].model.as_ref())
                .unwrap()
                .delta_wl
        })
        .sum::<f64>()
        / decided.len() as f64;
    assert!((rescored - c.test.delta_wl.mean).abs() < 1e-12);

    let dir = std::env::temp_dir().join(format!("hil-experiments-out-{}", std::process::id()));
    let reproduction = Reproduction::of(&settings, &models, &recs, "test data").unwrap();
    let w = hil_experiments::output::write_outputs(
        &dir,
        &reproduction,
        &recs,
        &models,
        &Default::default(),
    )
    .unwrap();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&w.results).unwrap()).unwrap();
    assert_eq!(v["paper_protocol"]["rows"].as_array().unwrap().len(), 16);
    assert!(v["many_seeds"].is_null());
    assert!(v["paper_protocol"]["provenance"].is_string() && v["timing"].is_object());
    // 2 models × (LinUCB, AQ, 2 c values, 3 w values).
    assert_eq!(v["frontier"].as_array().unwrap().len(), 2 * 7);
    assert_eq!(w.figures.len(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
    let md = hil_experiments::report::tables_markdown(&res, Some(1.0)).unwrap();
    assert!(md.contains("synthetic") || md.contains("test data"));
    assert!(md.contains("Cross-data"));
}

#[test]
fn bad_settings_are_errors_that_name_the_field() {
    use hil_core::HilError;
    let (ds, mut settings, models) = setup();
    settings.split = FoodSplit {
        test: vec![],
        ..FoodSplit::paper()
    };
    let p = Protocol::new(settings, ds.clone(), models.clone()).unwrap();
    let e = p.run_all(&|_, _| {}).unwrap_err().to_string();
    assert!(e.contains("split.test"), "{e}");

    let (ds, mut settings, models) = setup();
    settings.cross[0].score = "nope".into();
    let e = settings.validate(&ds, &models).unwrap_err();
    assert!(matches!(e, HilError::InvalidParameter { .. }), "{e:?}");

    // A cross-data method must read the workload forecast.
    let (ds, mut settings, models) = setup();
    settings.cross[0].method = "LinUCB".into();
    let e = settings.validate(&ds, &models).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "cross.method"));

    // Two tuned hyperparameters, duplicate labels, a grid value the policy refuses.
    let (ds, mut settings, models) = setup();
    settings.methods[3].tune.insert("alpha".into(), vec![0.1]);
    let e = settings.validate(&ds, &models).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "methods[3].tune"));
    let (ds, mut settings, models) = setup();
    settings.methods[1].label = "LinUCB".into();
    let e = settings.validate(&ds, &models).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "methods[1].label"));
    let (ds, mut settings, models) = setup();
    settings.methods[3].tune.insert("w".into(), vec![1.0, -1.0]);
    let e = Protocol::new(settings, ds, models)
        .unwrap()
        .run_all(&|_, _| {})
        .unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, value, .. }
            if name == "methods.LinUCB-QG" && value == "w = -1"),
        "{e:?}"
    );
}

#[test]
fn plots_render_runs() {
    let (ds, settings, models) = setup();
    let p = Protocol::new(settings, ds, models.clone()).unwrap();
    let ctx = p.build_context().unwrap();
    let rec = p
        .run_one(
            &RunKey {
                phase: Phase::Test,
                method: 1,
                point: None,
                decide_model: None,
                seed: 0,
                policy_seed: 0,
            },
            &ctx,
        )
        .unwrap();
    let m = models[1].model.as_ref();
    let svg = hil_experiments::plot::rollout_svg(&rec, m, "t", "synthetic").unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("<circle") && svg.trim_end().ends_with("</svg>")
    );
    assert_eq!(
        svg.matches("r=\"5\" fill=\"none\" stroke=\"red\"").count(),
        rec.metrics.queries.len()
    );
    let svg = hil_experiments::plot::workload_comparison_svg(&[("a", &rec), ("b", &rec)], m, "n")
        .unwrap();
    assert_eq!(svg.matches("<polyline").count(), 2);
}

/// A run key from outside `jobs()` (hil-py takes them as JSON) naming a
/// seed, policy seed or workload model the protocol does not have is an
/// error naming the field; an out-of-range model index panicked.
#[test]
fn a_run_key_outside_the_protocol_is_refused_naming_the_field() {
    use hil_core::HilError;
    let (ds, settings, models) = setup();
    let p = Protocol::new(settings, ds, models).unwrap();
    let ctx = p.build_context().unwrap();
    let jobs = p.jobs().unwrap();
    let good = jobs
        .iter()
        .find(|k| k.decide_model.is_some())
        .expect("a method that reads the forecast")
        .clone();
    let bad = [
        (
            "decide_model",
            RunKey {
                decide_model: Some(99),
                ..good.clone()
            },
        ),
        (
            "seed",
            RunKey {
                seed: usize::MAX,
                ..good.clone()
            },
        ),
        (
            "policy_seed",
            RunKey {
                policy_seed: usize::MAX,
                ..good.clone()
            },
        ),
        (
            "method",
            RunKey {
                method: 99,
                ..good.clone()
            },
        ),
    ];
    for (field, key) in bad {
        let e = p.run_one(&key, &ctx).unwrap_err();
        assert!(
            matches!(&e, HilError::InvalidParameter { name, .. } if name == field),
            "{field}: {e:?}"
        );
    }
}

/// A grid variant runs only its extra grid values, and is selected over
/// the same runs: its results choose only among its own values.
#[test]
fn a_grid_variant_runs_its_extra_values_once_and_selects_among_them() {
    let (ds, mut settings, models) = setup();
    let base = Protocol::new(settings.clone(), ds.clone(), models.clone())
        .unwrap()
        .jobs()
        .unwrap()
        .len();
    // c ∈ {0, 2} by default; the variant: {2, 5} (one new value).
    settings.grid_variants = vec![hil_experiments::grids::GridVariant {
        name: "other".into(),
        tune: [(
            "LinUCB-ExpDecay".to_string(),
            [("c".to_string(), vec![2.0, 5.0])].into(),
        )]
        .into(),
    }];
    let mut p = Protocol::new(settings.clone(), ds, models.clone()).unwrap();
    // One extra c × 3 policy seeds × 3 seeds × 2 phases.
    assert_eq!(p.jobs().unwrap().len(), base + 3 * 3 * 2);
    let r = Reproduction::of(&settings, &models, &run_all(&mut p, 2), "t").unwrap();
    assert_eq!(r.grid_variants.len(), 1);
    let v = &r.grid_variants[0];
    assert_eq!(v.settings.grid_name, "other");
    for row in v.rows.iter().filter(|x| x.method == "LinUCB-ExpDecay") {
        let c = row.selected.as_ref().unwrap().value;
        assert!(c == 2.0 || c == 5.0, "{c}");
    }
    for row in r
        .headline()
        .rows
        .iter()
        .filter(|x| x.method == "LinUCB-ExpDecay")
    {
        let c = row.selected.as_ref().unwrap().value;
        assert!(c == 0.0 || c == 2.0, "{c}");
    }
    // An unknown method in a variant is refused before anything runs.
    settings.grid_variants[0]
        .tune
        .insert("Nope".into(), Default::default());
    let ds = r.headline().settings.load_dataset().unwrap();
    assert!(settings.validate(&ds, &models).is_err());
    let p = Protocol::new(settings, ds, models).unwrap();
    assert!(matches!(
        p.jobs(),
        Err(hil_core::HilError::InvalidParameter { .. })
    ));
}

/// The many-seed run extends the paper-protocol run's seeds: its first
/// `n_seeds` seeds are the same episodes, so the paper-protocol tables are
/// the same whether or not the many-seed run is beside them.
#[test]
fn the_many_seed_run_contains_the_paper_protocol_run() {
    let (ds, mut settings, models) = setup();
    settings.methods.truncate(2);
    settings.cross.clear();
    settings.figures.rollout = "LinUCB".into();
    settings.figures.workload = vec!["AlwaysQuery".into()];
    let mut alone = Protocol::new(settings.clone(), ds.clone(), models.clone()).unwrap();
    let alone = Reproduction::of(&settings, &models, &run_all(&mut alone, 2), "t").unwrap();
    assert!(alone.many_seeds.is_none());
    settings.many_seeds = 6;
    let mut p = Protocol::new(settings.clone(), ds, models.clone()).unwrap();
    assert_eq!(p.jobs().unwrap().len(), 2 * 6 * 2);
    let both = Reproduction::of(&settings, &models, &run_all(&mut p, 2), "t").unwrap();
    let many = both.many_seeds.as_ref().unwrap();
    assert_eq!((many.n_env_seeds, many.spread), (6, Spread::Se));
    assert_eq!(both.paper_protocol.n_env_seeds, 3);
    assert_eq!(
        serde_json::to_value(&both.paper_protocol.rows).unwrap(),
        serde_json::to_value(&alone.paper_protocol.rows).unwrap()
    );
    let r = many.row("fast", 0.9, "AlwaysQuery").unwrap();
    assert_eq!(r.test.n_runs, 6);
    let s = r.test.r_task_avg;
    assert!((s.se - s.std * (6.0f64 / 5.0).sqrt() / 6f64.sqrt()).abs() < 1e-12);
    // The frontier: every (model, method, grid value), over all 6 seeds.
    assert_eq!(both.frontier.len(), 2 * 2);
    assert!(both.frontier.iter().all(|f| f.n_runs == 6));
}

#[test]
fn paper_protocol_config_file_matches_the_built_in_settings() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/configs/paper-protocol.toml");
    assert_eq!(
        ProtocolSettings::load(&path).unwrap(),
        ProtocolSettings::paper()
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = text.replace("n_seeds = 3", "n_seeds = 3\nn_seed = 2");
    let e = hil_config::parse_toml::<ProtocolSettings>(&bad, &path).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("n_seed"));
    // A method's policy table is checked as a policy config when parsed.
    let bad = text.replace("w = 1.0 }", "w = 1.0, omega = 2.0 }");
    let e = hil_config::parse_toml::<ProtocolSettings>(&bad, &path).unwrap_err();
    assert!(e.message.contains("omega"), "{e}");
}

#[test]
fn a_testbed_episode_and_an_experiment_file_episode_score_alike() {
    // The same episode (same components, same seeds) through the protocol
    // and through an experiment file, as `hil run` builds it: hil-core's one
    // scoring definition gives the same ΔWL and M_wt (and every other figure).
    let dataset = hil_envs::bundled_dataset().unwrap();
    let f2 = hil_workload::bundled::load("f2_sim").unwrap();
    let mut settings = ProtocolSettings::paper();
    settings.methods.truncate(4);
    settings.methods[3].tune.clear(); // LinUCB-QG at its table's w = 1
    let p = Protocol::new(
        settings.clone(),
        dataset,
        vec![NamedModel {
            name: "f2_sim".into(),
            model: f2,
        }],
    )
    .unwrap();
    let key = RunKey {
        phase: Phase::Test,
        method: 3,
        point: None,
        decide_model: Some(0),
        seed: 1,
        policy_seed: 0,
    };
    let rec = p.run_one(&key, &p.build_context().unwrap()).unwrap();
    assert!(rec.metrics.n_q > 0, "a querying episode: {:?}", rec.metrics);

    let quote = |v: &[String]| {
        v.iter()
            .map(|f| format!("\"{f}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let text = format!(
        r#"
seed = {seed}
[session]
n_att = 10
wl0 = 0.5
[environment]
type = "food_replay"
foods = [{test}]
pretrain_foods = [{pretrain}]
items_per_episode = 5
[policy]
type = "linucb_qg"
alpha = 0.5
lambda = 1.0
pretrain = true
w = 1.0
[workload]
type = "bundled"
name = "f2_sim"
[channel]
type = "simulated_expert"
"#,
        seed = settings.seed,
        test = quote(&settings.split.test),
        pretrain = quote(&settings.split.pretrain),
    );
    let path = std::path::Path::new("episode.toml");
    let cfg = hil_experiments::ExperimentConfig::parse(&text, path).unwrap();
    let mut exp = cfg.build(std::path::Path::new(".")).unwrap();
    let (label, seeds) = p.seeds(&key);
    let report = hil_core::Session::new(
        exp.settings.clone(),
        exp.environment.as_mut(),
        exp.policy.as_mut(),
        exp.channel.as_mut(),
        exp.workload.clone(),
    )
    .run_episode_with_seeds(label, seeds, &mut [])
    .unwrap();
    let m = &report.metrics;
    assert_eq!(m.delta_wl, rec.metrics.delta_wl);
    assert_eq!(m.m_wt(0.7), rec.metrics.m_wt(0.7));
    assert_eq!(m, &rec.metrics);
}

#[test]
fn settings_counts_are_bounded_and_located() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/configs/paper-protocol.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let dir = std::env::temp_dir().join(format!("hil-testbed-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (from, to, field) in [
        ("many_seeds = 30", "many_seeds = 4294967296", "many_seeds"),
        ("n_seeds = 3 ", "n_seeds = 0 ", "n_seeds"),
        (
            "items_per_episode = 5",
            "items_per_episode = 9223372036854775807",
            "items_per_episode",
        ),
        // A food the dataset lacks, in the split: located too (issue 31).
        (
            "validation = [\"cantaloupe\", \"grape\"]",
            "validation = [\"cantaloupe\", \"grapefruit\"]",
            "split.validation",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let p = dir.join("s.toml");
        std::fs::write(&p, text.replace(from, to)).unwrap();
        match ProtocolSettings::load(&p).unwrap_err() {
            hil_core::HilError::Config(e) => {
                assert_eq!(e.field.as_deref(), Some(field));
                assert!(e.line > 1, "{e}");
            }
            other => panic!("{other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
