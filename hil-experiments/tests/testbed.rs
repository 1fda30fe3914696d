//! The protocol end to end on a small dataset, with small real policies
//! written here (the LinUCB family lives in hil-policies, which hil-envs does
//! not depend on) and hil-core's counting workload model.

use std::sync::Arc;

use hil_core::testing::fixtures::CountingWorkload;
use hil_core::{ArmId, Decision, DecisionInput, Feedback, Policy, QueryKind, Result};
use hil_envs::generate::SyntheticFoods;
use hil_envs::protocol::{
    CrossSetting, Family, NamedModel, PolicySpec, Protocol, ProtocolSettings,
};
use hil_envs::results::aggregate;
use hil_envs::{FoodDataset, FoodSplit};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Acts with arm 0 unless told to query: AlwaysQuery always, ExpDecay with
/// probability e^{−cN} at an item's first attempt, QG when
/// w · WL_if_queried < 1.
struct Simple {
    spec: PolicySpec,
    dim: usize,
    rng: ChaCha8Rng,
}

impl Policy for Simple {
    fn name(&self) -> &str {
        "simple"
    }
    fn n_arms(&self) -> usize {
        6
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        let k = QueryKind::default();
        let query = match self.spec {
            PolicySpec::Linucb => false,
            PolicySpec::AlwaysQuery => true,
            PolicySpec::LinucbExpDecay { c } => {
                input.attempt == 0
                    && self.rng.random::<f64>() < (-c * input.items_seen as f64).exp()
            }
            PolicySpec::LinucbQg { w } => w * input.workload.if_queried(k)? < 1.0,
        };
        Ok(if query {
            Decision::query(k, ArmId(0))
        } else {
            Decision::act(ArmId(0))
        })
    }
    fn observe(&mut self, _f: &Feedback<'_>) -> Result<()> {
        Ok(())
    }
}

fn setup() -> (Arc<FoodDataset>, ProtocolSettings, Vec<NamedModel>) {
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
    let settings = ProtocolSettings {
        n_policy_seeds: 3,
        w_tasks: vec![0.2, 0.9],
        qg_w: vec![0.5, 1.5, 3.0],
        exp_decay_c: vec![0.0, 2.0],
        cross: vec![CrossSetting {
            decide: "slow".into(),
            score: "fast".into(),
        }],
        ..ProtocolSettings::paper()
    };
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

fn factory(spec: &PolicySpec) -> Result<Box<dyn Policy>> {
    Ok(Box::new(Simple {
        spec: *spec,
        dim: 224,
        rng: ChaCha8Rng::seed_from_u64(0),
    }))
}

#[test]
fn protocol_runs_selects_on_validation_and_is_deterministic() {
    let (ds, settings, models) = setup();
    let p = Protocol {
        settings: settings.clone(),
        dataset: ds.clone(),
        models: models.clone(),
        factory: &factory,
    };
    // 2 phases × 3 seeds × (LinUCB + AQ + 2 c × 3 policy seeds + 3 w × 2 models).
    assert_eq!(p.jobs().len(), 2 * 3 * (1 + 1 + 6 + 6));
    let seen = std::sync::atomic::AtomicUsize::new(0);
    let recs = p
        .run_all(2, &|_, _| {
            seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
    assert_eq!(seen.into_inner(), recs.len());
    let recs1 = p.run_all(1, &|_, _| {}).unwrap();
    let json = |r: &[hil_envs::protocol::RunRecord]| serde_json::to_string(r).unwrap();
    assert_eq!(json(&recs), json(&recs1), "thread count changed results");

    let res = aggregate(&settings, &models, &recs, "test data").unwrap();
    assert_eq!(res.rows.len(), 2 * 2 * 4);
    for r in &res.rows {
        match r.policy {
            Family::AlwaysQuery => assert_eq!(r.test.f_q.mean, 1.0),
            Family::Linucb => {
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
    // Under the fast model at w_task = 0.2 workload dominates: QG picks a
    // large w (fewer queries) and queries less than under w_task = 0.9.
    let lo = res.row("fast", 0.2, Family::LinucbQg).unwrap();
    let hi = res.row("fast", 0.9, Family::LinucbQg).unwrap();
    assert!(lo.test.f_q.mean <= hi.test.f_q.mean);
    // Cross row: QG decided with `slow`, w chosen as in the slow row, scored with `fast`.
    let c = &res.cross[0];
    let slow = res.row("slow", 0.4, Family::LinucbQg);
    assert!(slow.is_none()); // 0.4 is not in w_tasks; selection still ran for the cross row
    assert_eq!(c.test.n_runs, 3);
    let dir = std::env::temp_dir().join(format!("hil-envs-out-{}", std::process::id()));
    let w = hil_envs::output::write_outputs(
        &dir,
        &res,
        &recs,
        &models,
        "fast",
        0.9,
        &Default::default(),
    )
    .unwrap();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&w.results).unwrap()).unwrap();
    assert_eq!(v["rows"].as_array().unwrap().len(), 16);
    assert!(v["provenance"].is_string() && v["timing"].is_object());
    assert_eq!(w.figures.len(), 2);
    std::fs::remove_dir_all(&dir).unwrap();
    let md = hil_envs::report::tables_markdown(&res, Some(1.0));
    assert!(md.contains("synthetic") || md.contains("test data"));
    assert!(md.contains("Cross-data"));
}

#[test]
fn bad_settings_are_errors() {
    let (ds, mut settings, models) = setup();
    settings.split = FoodSplit {
        test: vec![],
        ..FoodSplit::paper()
    };
    let p = Protocol {
        settings,
        dataset: ds.clone(),
        models: models.clone(),
        factory: &factory,
    };
    let e = p.run_all(1, &|_, _| {}).unwrap_err().to_string();
    assert!(e.contains("split.test"), "{e}");
    let (ds, mut settings, models) = setup();
    settings.cross[0].score = "nope".into();
    let p = Protocol {
        settings,
        dataset: ds,
        models,
        factory: &factory,
    };
    assert!(
        p.run_all(1, &|_, _| {})
            .unwrap_err()
            .to_string()
            .contains("nope")
    );
}

#[test]
fn plots_render_runs() {
    let (ds, settings, models) = setup();
    let p = Protocol {
        settings,
        dataset: ds,
        models: models.clone(),
        factory: &factory,
    };
    let rec = p
        .run_one(&hil_envs::protocol::RunKey {
            phase: hil_envs::protocol::Phase::Test,
            spec: PolicySpec::AlwaysQuery,
            decide_model: None,
            seed: 0,
            policy_seed: 0,
        })
        .unwrap();
    let m = models[1].model.as_ref();
    let svg = hil_envs::plot::rollout_svg(&rec, m, 0.5, "t", "synthetic").unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("<circle") && svg.trim_end().ends_with("</svg>")
    );
    assert_eq!(
        svg.matches("r=\"5\" fill=\"none\" stroke=\"red\"").count(),
        rec.queries.len()
    );
    let svg =
        hil_envs::plot::workload_comparison_svg(&[("a", &rec), ("b", &rec)], m, 0.5, "n").unwrap();
    assert_eq!(svg.matches("<polyline").count(), 2);
}

#[test]
fn paper_protocol_config_file_matches_the_built_in_settings() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/configs/paper-protocol.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let parsed: ProtocolSettings = hil_core::config::parse_toml(&text, &path).unwrap();
    assert_eq!(parsed, ProtocolSettings::paper());
    let bad = text.replace("n_seeds = 3", "n_seeds = 3\nn_seed = 2");
    let e = hil_core::config::parse_toml::<ProtocolSettings>(&bad, &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("n_seed"), "{e}");
}
