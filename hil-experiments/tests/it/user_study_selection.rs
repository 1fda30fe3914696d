//! The user study's validation phase: a tuned method's hyperparameter (LinUCB-QG's
//! w) is chosen by the highest mean M_wt over simulated validation plates,
//! and the study then runs that value.

use std::path::Path;

use hil_core::WorkloadInput;
use hil_experiments::user_study::UserStudyConfig;
use hil_paper::methods::QG_W_GRID;

/// A cheap environment in place of the MuJoCo scene (the bundled synthetic
/// food dataset), with pretraining foods because the methods pretrain.
const CHEAP_ENV: &str = r#"
[environment]
type = "food_replay"
foods = ["banana", "carrot", "cantaloupe"]
pretrain_foods = ["apple", "kiwi", "strawberry"]
items_per_episode = 3
"#;

fn study(methods: &str) -> UserStudyConfig {
    let text = format!(
        "repetitions = 2\nseed = 3\n{CHEAP_ENV}\n[validation]\nplates = 3\nw_task = 0.7\n{methods}"
    );
    UserStudyConfig::parse(&text, Path::new("study.toml")).unwrap()
}

const QG_TUNED: &str = r#"
[[methods]]
label = "LinUCB-QG"
policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, w = 1.0, pretrain = true }
tune = { w = [0.25, 2.0, 32.0] }
"#;

#[test]
fn w_is_the_grid_value_with_the_highest_validation_m_wt_and_the_study_uses_it() {
    let cfg = study(QG_TUNED);
    let result = cfg.run(Path::new("."), |_| {}).unwrap();
    assert_eq!(result.selections.len(), 1);
    let sel = &result.selections[0];
    assert_eq!(
        (sel.method.as_str(), sel.parameter.as_str()),
        ("LinUCB-QG", "w")
    );
    assert_eq!(sel.grid, [0.25, 2.0, 32.0]);
    assert_eq!((sel.plates, sel.w_task), (3, 0.7));
    // The chosen value has the highest mean M_wt (the first among ties).
    let best = sel
        .m_wt
        .iter()
        .map(|m| m.mean)
        .fold(f64::NEG_INFINITY, f64::max);
    let first_best = sel.m_wt.iter().position(|m| m.mean == best).unwrap();
    assert_eq!(sel.chosen, sel.grid[first_best], "{sel:?}");
    // A larger w trusts the workload forecast more: it never asks more.
    assert!(sel.n_q[0] >= sel.n_q[2], "{sel:?}");
    // The study's plates are those of the untuned method at the chosen w.
    let fixed = study(&format!(
        r#"
[[methods]]
label = "LinUCB-QG"
policy = {{ type = "linucb_qg", alpha = 0.5, lambda = 1.0, w = {}, pretrain = true }}
"#,
        sel.chosen
    ))
    .run(Path::new("."), |_| {})
    .unwrap();
    assert!(fixed.selections.is_empty());
    assert_eq!(fixed.plates, result.plates);
}

#[test]
fn the_paper_protocol_chooses_w_on_validation_not_by_hand() {
    let cfg = UserStudyConfig::paper();
    let qg = cfg.methods.iter().find(|m| m.label == "LinUCB-QG").unwrap();
    assert_eq!(qg.tune.get("w").map(Vec::as_slice), Some(&QG_W_GRID[..]));
    assert!(cfg.validation.plates >= 1);
    // The other methods have nothing to tune.
    assert!(
        cfg.methods
            .iter()
            .filter(|m| m.label != "LinUCB-QG")
            .all(|m| m.tune.is_empty())
    );
}

#[test]
fn zero_validation_plates_are_refused_by_name() {
    let err =
        UserStudyConfig::parse("[validation]\nplates = 0\n", Path::new("study.toml")).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("validation.plates"), "{err}");
}

#[test]
fn the_study_workload_model_never_forecasts_less_workload_for_a_query() {
    use hil_core::{QueryHistory, QueryKind};
    use hil_experiments::user_study::PAPER_WORKLOAD;
    let model = hil_workload::bundled::load(PAPER_WORKLOAD).unwrap();
    let kinds: Vec<QueryKind> = [
        "mcq/easy/none",
        "bounding_box/hard/easy",
        "open_ended/hard/hard",
        "mcq/hard/easy",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    // Histories of 0–6 queries at irregular times, every WL_0.
    for wl0 in [0.0, 0.3, 0.5, 0.9] {
        for n in 0..=6u64 {
            let mut h = QueryHistory::new();
            for i in 0..n {
                h.push(1 + 3 * i + i * i % 4, kinds[i as usize % kinds.len()])
                    .unwrap();
            }
            let t = 2 + 3 * n + n * n % 4;
            let now = model.predict(&WorkloadInput::new(wl0, &h, t)).unwrap();
            for &k in &kinds {
                let asked = model
                    .predict_if_queried(&WorkloadInput::new(wl0, &h, t), k)
                    .unwrap();
                assert!(
                    asked >= now - 1e-12,
                    "{PAPER_WORKLOAD}: WL_0 {wl0}, {n} queries, {k}: {asked} < {now}"
                );
            }
        }
    }
    // The fitted real-data model does not have this property: that is why
    // the study does not use it.
    let real = hil_workload::bundled::load("f12_real").unwrap();
    let h = QueryHistory::new();
    let falls = kinds.iter().any(|&k| {
        real.predict_if_queried(&WorkloadInput::new(0.5, &h, 1), k)
            .unwrap()
            < real.predict(&WorkloadInput::new(0.5, &h, 1)).unwrap()
    });
    assert!(falls);
}
