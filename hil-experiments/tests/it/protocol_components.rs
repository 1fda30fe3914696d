//! The testbed protocol's pluggable parts (`hil_experiments::components`):
//! the default channel and environment reproduce the paper's runs bit for
//! bit, the same types named in the settings give the same records, a
//! different channel or environment changes the results the expected way,
//! a workload model of any registered type joins the protocol, and a raised
//! cancel flag stops the run.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use hil_config::TaskContext;
use hil_conformance::fixtures::TableEnv;
use hil_core::{ArmId, HilError, Query, QueryChannel, Response};
use hil_envs::DatasetReplayEnv;
use hil_experiments::components::{EnvironmentFactory, EpisodeSpec};
use hil_experiments::testbed::{ModelSource, Phase, RunOutcome, RunRecord};
use hil_experiments::{Protocol, ProtocolSettings};

use super::testbed::setup;

/// The setup's settings cut to LinUCB, AlwaysQuery and LinUCB-QG at one
/// w, with no cross-data rows, so a run is a few dozen episodes.
fn small() -> (Protocol, ProtocolSettings) {
    let (ds, mut settings, models) = setup();
    settings.methods.remove(2); // LinUCB-ExpDecay
    settings.methods[2].tune.clear();
    settings.cross.clear();
    settings.figures.workload = vec!["AlwaysQuery".into()];
    let p = Protocol::new(settings.clone(), ds, models).unwrap();
    (p, settings)
}

fn json(records: &[RunRecord]) -> String {
    serde_json::to_string(records).unwrap()
}

fn table(text: &str) -> toml::Table {
    text.parse().unwrap()
}

/// Mean task success and query count of `method`'s test runs.
fn success_and_queries(records: &[RunRecord], method: usize) -> (f64, f64) {
    let runs: Vec<_> = records
        .iter()
        .filter(|r| r.key.phase == Phase::Test && r.key.method == method)
        .collect();
    let n = runs.len() as f64;
    let s = runs.iter().map(|r| r.metrics.r_task_avg).sum::<f64>() / n;
    let q = runs.iter().map(|r| r.metrics.n_q as f64).sum::<f64>() / n;
    (s, q)
}

/// An expert who always names the action after the best one.
struct WrongExpert;

impl QueryChannel for WrongExpert {
    fn name(&self) -> &str {
        "wrong_expert"
    }

    fn ask(&mut self, query: &Query) -> hil_core::Result<Response> {
        let best = query
            .oracle_best
            .expect("the dataset knows the best action");
        Ok(Response::action(ArmId((best.0 + 1) % query.actions.len())))
    }
}

#[test]
fn the_settings_types_of_the_defaults_give_the_default_records() {
    let (p, mut settings) = small();
    // A configured environment reads the settings' dataset: save the
    // setup's where the settings name it.
    let dir = std::env::temp_dir().join(format!("hil-protocol-components-{}", std::process::id()));
    let path = p.dataset.save(&dir).unwrap();
    settings.dataset = Some(path.clone());
    let dataset = Arc::new(hil_envs::FoodDataset::load(&path).unwrap());
    let p = Protocol::new(settings.clone(), dataset, p.models.clone()).unwrap();
    let default = json(&p.run_all(&|_, _| {}).unwrap());
    let mut named = settings.clone();
    named.environment = Some(table(r#"type = "food_replay""#));
    named.channel = Some(table(r#"type = "simulated_expert""#));
    let named = Protocol::new(named, p.dataset.clone(), p.models.clone()).unwrap();
    assert_eq!(json(&named.run_all(&|_, _| {}).unwrap()), default);
    std::fs::remove_dir_all(&dir).unwrap();
    // And the settings say nothing new when nothing is set: a settings file
    // written before these fields existed reads the same.
    let text = serde_json::to_string(&settings).unwrap();
    assert!(!text.contains("\"channel\"") && !text.contains("\"environment\""));
}

#[test]
fn an_expert_naming_a_wrong_arm_lowers_success() {
    let (p, settings) = small();
    let right = p.run_all(&|_, _| {}).unwrap();
    let wrong = Protocol::new(settings.clone(), p.dataset.clone(), p.models.clone())
        .unwrap()
        .with_channel(Arc::new(|_: &TaskContext| {
            Ok(Box::new(WrongExpert) as Box<dyn QueryChannel>)
        }))
        .run_all(&|_, _| {})
        .unwrap();
    // AlwaysQuery (method 1) acts on every answer.
    let (s_right, q_right) = success_and_queries(&right, 1);
    let (s_wrong, q_wrong) = success_and_queries(&wrong, 1);
    assert_eq!(q_right, q_wrong);
    assert!(s_wrong < s_right, "{s_wrong} !< {s_right}");
    // The same through the settings: an expert who is never right.
    let mut never = settings;
    never.channel = Some(table("type = \"simulated_expert\"\nerror_rate = 1.0"));
    let never = Protocol::new(never, p.dataset.clone(), p.models.clone())
        .unwrap()
        .run_all(&|_, _| {})
        .unwrap();
    assert!(success_and_queries(&never, 1).0 < s_right);
    // LinUCB never asks, so the channel changes nothing for it.
    assert_eq!(
        success_and_queries(&wrong, 0),
        success_and_queries(&right, 0)
    );
}

#[test]
fn an_environment_factory_sets_every_episode() {
    let (p, _) = small();
    // One item per episode instead of the settings' five.
    let one_item = |spec: &EpisodeSpec<'_>| -> hil_core::Result<Box<dyn hil_core::Environment>> {
        Ok(Box::new(DatasetReplayEnv::new(
            spec.dataset.clone(),
            spec.foods,
            1,
        )?))
    };
    assert_eq!(one_item.name(), "custom environment factory");
    let p = p.with_environment(Arc::new(one_item));
    let records = p.run_all(&|_, _| {}).unwrap();
    assert!(records.iter().all(|r| r.metrics.n_items == 1));
}

#[test]
fn bad_channel_and_environment_tables_are_named() {
    let (p, settings) = small();
    let new = |s: ProtocolSettings| Protocol::new(s, p.dataset.clone(), p.models.clone());

    let mut s = settings.clone();
    s.channel = Some(table(r#"type = "no_such_channel""#));
    let e = new(s).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "channel"));

    let mut s = settings.clone();
    s.channel = Some(table("type = \"simulated_expert\"\np_correct = 2.0"));
    let e = new(s).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "channel"));

    let mut s = settings.clone();
    s.environment = Some(table("type = \"food_replay\"\nfoods = [\"apple\"]"));
    let e = new(s).unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "environment.foods"));

    // An environment with other actions than the dataset's fails the run,
    // naming the environment.
    let other = |_: &EpisodeSpec<'_>| -> hil_core::Result<Box<dyn hil_core::Environment>> {
        let actions = hil_core::ActionSpace::new(["skewer", "scoop"])?;
        Ok(Box::new(TableEnv::new(
            actions,
            vec![("pea", vec![0.2, 0.9])],
        )?))
    };
    let e = new(settings)
        .unwrap()
        .with_environment(Arc::new(other))
        .run_all(&|_, _| {})
        .unwrap_err();
    assert!(e.to_string().contains("not the dataset's"), "{e}");
}

#[test]
fn a_workload_model_of_a_registered_type_joins_the_protocol() {
    let (p, mut settings) = small();
    settings.models = vec![
        ModelSource::bundled("f2_sim"),
        ModelSource::configured("f2_again", table("type = \"bundled\"\nname = \"f2_sim\"")),
    ];
    settings.figures.model = "f2_sim".into();
    let models = settings.load_models().unwrap();
    let p = Protocol::new(settings.clone(), p.dataset.clone(), models).unwrap();
    let records = p.run_all(&|_, _| {}).unwrap();
    // LinUCB-QG (method 2) decides once per model; the two models are one.
    let by_model = |d: usize| -> Vec<String> {
        records
            .iter()
            .filter(|r| r.key.method == 2 && r.key.decide_model == Some(d))
            .map(|r| serde_json::to_string(&r.steps).unwrap())
            .collect()
    };
    assert!(!by_model(0).is_empty());
    assert_eq!(by_model(0), by_model(1));

    settings.models[1] = ModelSource::configured("bad", table(r#"type = "nope""#));
    let e = settings.load_models().unwrap_err();
    assert!(matches!(&e, HilError::InvalidParameter { name, .. } if name == "models[1].config"));
}

#[test]
fn a_raised_cancel_flag_stops_the_run() {
    let (mut p, _) = small();
    let total = p.jobs().unwrap().len();
    let cancel = AtomicBool::new(true);
    match p.run_until_cancelled(&|_, _| {}, &cancel).unwrap() {
        RunOutcome::Cancelled { done, total: t } => assert_eq!((done, t), (0, total)),
        RunOutcome::Finished(_) => panic!("a raised flag must stop the run"),
    }
    // Raised after three jobs (as a Ctrl-C handler would, mid-run).
    let cancel = AtomicBool::new(false);
    p.runner = hil_jobs::Runner::new(2).unwrap();
    let outcome = p
        .run_until_cancelled(
            &|done, _| {
                if done >= 3 {
                    cancel.store(true, Ordering::Relaxed);
                }
            },
            &cancel,
        )
        .unwrap();
    match outcome {
        // At most one more job per worker thread after the flag.
        RunOutcome::Cancelled { done, .. } => assert!((3..=5).contains(&done), "{done}"),
        RunOutcome::Finished(_) => panic!("the flag was raised mid-run"),
    }
    let cancel = AtomicBool::new(false);
    assert!(matches!(
        p.run_until_cancelled(&|_, _| {}, &cancel).unwrap(),
        RunOutcome::Finished(r) if r.len() == total
    ));
}

/// A channel that fails at its first query.
struct Offline;

impl QueryChannel for Offline {
    fn name(&self) -> &str {
        "offline"
    }

    fn ask(&mut self, _query: &Query) -> hil_core::Result<Response> {
        Err(HilError::channel("offline", "the tablet is off"))
    }
}

#[test]
fn a_failing_component_keeps_its_error_kind_and_names_the_run() {
    let (p, _) = small();
    let e = p
        .with_channel(Arc::new(|_: &TaskContext| {
            Ok(Box::new(Offline) as Box<dyn QueryChannel>)
        }))
        .run_all(&|_, _| {})
        .unwrap_err();
    match &e {
        HilError::Channel { channel, why, .. } => {
            assert_eq!(channel, "offline");
            assert!(
                why.contains("the tablet is off") && why.contains("run of `"),
                "{why}"
            );
        }
        other => panic!("expected a channel error, got {other:?}"),
    }
}

#[test]
fn a_settings_file_with_an_unknown_channel_type_names_file_line_and_field() {
    let dir = std::env::temp_dir().join(format!("hil-protocol-settings-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("settings.toml");
    let mut text = toml::to_string(&ProtocolSettings::quick()).unwrap();
    text = format!("channel = {{ type = \"no_such_expert\" }}\n{text}");
    std::fs::write(&path, &text).unwrap();
    let e = ProtocolSettings::load(&path).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    match &e {
        HilError::Config(c) => {
            assert_eq!((c.line, c.field.as_deref()), (1, Some("channel")), "{e}");
            assert!(e.to_string().contains("settings.toml"), "{e}");
        }
        other => panic!("expected a config error, got {other:?}"),
    }
}
