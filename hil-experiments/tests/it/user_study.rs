//! The user-study protocol as a library: its file format, its errors and a
//! run on a cheap environment (the bundled synthetic food dataset).

use std::path::Path;

use hil_core::ConfigError;
use hil_core::{SessionObserver, StepEvent};
use hil_experiments::user_study::{UserStudyConfig, method_order};

/// A cheap environment in place of the MuJoCo scene, with pretraining foods
/// because the paper's methods pretrain.
const CHEAP_ENV: &str = r#"
[environment]
type = "food_replay"
foods = ["banana", "carrot"]
pretrain_foods = ["apple", "kiwi", "strawberry"]
items_per_episode = 3
"#;

fn parse(text: &str) -> Result<UserStudyConfig, ConfigError> {
    UserStudyConfig::parse(text, Path::new("study.toml"))
}

fn as_toml(cfg: &UserStudyConfig) -> toml::Value {
    toml::Value::try_from(cfg).expect("a study config serialises")
}

#[test]
fn shipped_file_is_the_paper_protocol() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/configs/user-study.toml");
    let file = UserStudyConfig::load(&path).unwrap();
    assert_eq!(as_toml(&file), as_toml(&UserStudyConfig::paper()));
}

#[test]
#[cfg(feature = "physics")]
fn an_empty_file_is_the_paper_protocol() {
    assert_eq!(
        as_toml(&parse("").unwrap()),
        as_toml(&UserStudyConfig::paper())
    );
}

/// A build without MuJoCo cannot run the default scene, so it refuses a
/// file that leaves the environment out, naming the file and the table.
#[test]
#[cfg(not(feature = "physics"))]
fn without_physics_a_file_must_name_its_environment() {
    let err = parse("repetitions = 1\n").unwrap_err();
    assert_eq!(err.field.as_deref(), Some("environment"), "{err}");
    let shown = err.to_string();
    assert!(shown.contains("study.toml"), "{shown}");
    assert!(shown.contains("--features physics"), "{shown}");
    // Other errors of the file come first, at their own keys.
    let err = parse("repetitions = 0\n").unwrap_err();
    assert_eq!(err.field.as_deref(), Some("repetitions"), "{err}");
    // Naming one is enough.
    assert!(parse(&format!("repetitions = 1\n{CHEAP_ENV}")).is_ok());
}

/// The paper's protocol runs on any environment, without physics.
#[test]
fn the_paper_protocol_runs_on_another_environment() {
    let env = parse(CHEAP_ENV).unwrap().environment;
    let mut cfg = UserStudyConfig::paper_on(env);
    cfg.repetitions = 1;
    let paper = UserStudyConfig::paper();
    assert_eq!(cfg.labels(), paper.labels());
    assert_eq!(cfg.validation, paper.validation);
    let result = cfg.run(Path::new("."), |_| {}).unwrap();
    assert_eq!(result.protocol.environment, "food_replay");
    assert_eq!(result.plates.len(), 3);
}

#[test]
fn written_out_config_reads_back_the_same() {
    let cfg = parse(&format!("repetitions = 1\n{CHEAP_ENV}")).unwrap();
    let again = parse(&cfg.to_toml().unwrap()).unwrap();
    assert_eq!(as_toml(&again), as_toml(&cfg));
}

#[test]
fn session_merges_over_the_papers() {
    let cfg = parse(&format!("[session]\nwl0 = 0.25\n{CHEAP_ENV}")).unwrap();
    assert_eq!((cfg.session.n_att, cfg.session.wl0), (3, 0.25));
}

#[test]
fn a_channel_table_replaces_the_default_channel() {
    let cfg = parse(&format!(
        "[channel]\ntype = \"simulated_expert\"\nerror_rate = 0.2\n{CHEAP_ENV}"
    ))
    .unwrap();
    let channel = &as_toml(&cfg)["channel"];
    assert_eq!(channel["error_rate"].as_float(), Some(0.2));
}

/// Where an error points: (line, field).
fn located(err: &ConfigError) -> (usize, Option<&str>) {
    (err.line, err.field.as_deref())
}

#[test]
fn unknown_channel_field_is_located() {
    let text = "seed = 1\n[channel]\ntype = \"simulated_expert\"\nerror_rat = 0.2\n";
    let err = parse(text).unwrap_err();
    assert_eq!(err.path, Path::new("study.toml"));
    assert_eq!(located(&err), (4, Some("channel.error_rat")));
}

#[test]
fn bad_policy_value_is_located() {
    let text = r#"
[[methods]]
label = "LinUCB"
[methods.policy]
type = "linucb"
alpha = "high"
"#;
    let err = parse(text).unwrap_err();
    assert_eq!(err.line, 6, "{err}");
    assert_eq!(err.field.as_deref(), Some("methods.policy.alpha"), "{err}");
}

#[test]
fn two_tuned_hyperparameters_are_refused_by_name() {
    let text = "[[methods]]\nlabel = \"QG\"\npolicy = { type = \"linucb_qg\", alpha = 0.5, w = 1.0 }\ntune = { w = [1.0, 2.0], alpha = [0.5] }\n";
    let err = parse(text).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("methods.tune"), "{err}");
    assert_eq!(err.line, 4, "{err}");
}

#[test]
fn unknown_policy_type_is_located() {
    let text = "[[methods]]\nlabel = \"X\"\npolicy = { type = \"linucbb\", alpha = 0.5 }\n";
    let err = parse(text).unwrap_err();
    assert_eq!(err.line, 3, "{err}");
    assert!(
        err.field
            .as_deref()
            .is_some_and(|f| f.starts_with("methods")),
        "{err}"
    );
}

#[test]
fn counts_are_validated() {
    let err = parse("seed = 1\nrepetitions = 0\n").unwrap_err();
    assert_eq!(located(&err), (2, Some("repetitions")));
    // A count above its limit is refused before anything is allocated.
    let err = parse("repetitions = 100001\n").unwrap_err();
    assert_eq!(located(&err), (1, Some("repetitions")));
    let err = parse("[validation]\nplates = 9223372036854775807\n").unwrap_err();
    assert_eq!(located(&err), (2, Some("validation.plates")));

    let err = parse("methods = []\n").unwrap_err();
    assert_eq!(located(&err), (1, Some("methods")));

    let err = parse("[session]\nn_att = 0\n").unwrap_err();
    assert_eq!(located(&err), (2, Some("session.n_att")));
    let err = parse("[session]\nn_att = 1001\n").unwrap_err();
    assert_eq!(located(&err), (2, Some("session.n_att")));
}

/// A bad value of any component (environment, workload, channel, a
/// method's policy or a value of its grid) is found when the file is read,
/// at its line, not when the study builds it.
#[test]
fn component_values_are_located_when_the_file_is_read() {
    let env = "[environment]\ntype = \"food_replay\"\nfoods = [\"banana\"]\n";
    let err = parse(&format!("{env}items_per_episode = 0\n")).unwrap_err();
    assert_eq!(located(&err), (4, Some("environment.items_per_episode")));

    let policy = "[[methods]]\nlabel = \"L\"\n[methods.policy]\ntype = \"linucb\"\n";
    let err = parse(&format!("{CHEAP_ENV}{policy}alpha = -1.0\n")).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("methods.policy.alpha"), "{err}");
    assert_eq!(err.line, CHEAP_ENV.lines().count() + 5, "{err}");

    let tuned = "[[methods]]\nlabel = \"L\"\ntune = { alpha = [0.5, -1.0] }\n\
                 [methods.policy]\ntype = \"linucb\"\nalpha = 1.0\n";
    let err = parse(&format!("{CHEAP_ENV}{tuned}")).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("methods.tune.alpha"), "{err}");

    let channel = "[channel]\ntype = \"simulated_expert\"\nerror_rate = 2.0\n";
    let err = parse(&format!("{CHEAP_ENV}{channel}")).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("channel.error_rate"), "{err}");
}

#[test]
fn duplicate_labels_are_located() {
    let text = r#"
[[methods]]
label = "A"
policy = { type = "linucb", alpha = 0.5 }
[[methods]]
label = "A"
policy = { type = "always_query", alpha = 0.5 }
"#;
    let err = parse(text).unwrap_err();
    assert_eq!(located(&err), (6, Some("methods[1].label")));
}

#[test]
fn unknown_top_level_key_is_located() {
    let err = parse("seed = 1\nrepetitionz = 2\n").unwrap_err();
    assert_eq!(located(&err), (2, Some("repetitionz")));
}

#[test]
fn runs_every_method_in_counterbalanced_order() {
    let cfg = parse(&format!("repetitions = 2\n{CHEAP_ENV}")).unwrap();
    let mut seen = 0;
    let result = cfg.run(Path::new("."), |_| seen += 1).unwrap();
    assert_eq!(seen, 6);
    assert_eq!(result.plates.len(), 6);
    let labels = cfg.labels();
    for (i, p) in result.plates.iter().enumerate() {
        let (rep, pos) = (i / 3, i % 3);
        assert_eq!(p.method, labels[method_order(rep, 3)[pos]]);
        assert_eq!((p.repetition, p.position), (rep + 1, pos + 1));
        assert!(p.n_success <= 3 && p.n_steps >= 3 && p.n_steps <= 9);
    }
    assert_eq!(result.protocol.environment, "food_replay");
    assert_eq!(result.protocol.n_att, 3);
    for (m, label) in result.methods.iter().zip(&labels) {
        assert_eq!((&m.method, m.plates), (&label.to_string(), 2));
        assert!(m.r_task_avg_sem.is_some() && m.n_q_per_plate_sem.is_some());
    }
    // AlwaysQuery asks at every item.
    assert!(result.methods[1].n_q_per_plate >= 3.0);
    // The same seed gives the same study.
    assert_eq!(cfg.run(Path::new("."), |_| {}).unwrap(), result);
}

#[test]
fn a_noisy_channel_changes_answers_not_the_protocol() {
    let cfg = parse(&format!(
        "repetitions = 1\n{CHEAP_ENV}\n[channel]\ntype = \"simulated_expert\"\nerror_rate = 0.5\n"
    ))
    .unwrap();
    let result = cfg.run(Path::new("."), |_| {}).unwrap();
    assert_eq!(result.plates.len(), 3);
    assert!(result.methods.iter().all(|m| m.r_task_avg_sem.is_none()));
}

#[derive(Default)]
struct CountSteps(usize);

impl SessionObserver for CountSteps {
    fn on_step(&mut self, _: &StepEvent) -> hil_core::Result<()> {
        self.0 += 1;
        Ok(())
    }
}

#[test]
fn run_with_lets_the_caller_observe_every_plate() {
    let cfg = parse(&format!("repetitions = 1\n{CHEAP_ENV}")).unwrap();
    let mut env = cfg.build_environment(Path::new(".")).unwrap();
    let mut study = cfg.prepare(Path::new("."), env.as_ref()).unwrap();
    assert_eq!(study.schedule().len(), 3);
    let mut steps = CountSteps::default();
    let mut plates = Vec::new();
    let result = study
        .run_with(
            env.as_mut(),
            |plate, env, episode| {
                // Validation plates (repetition 0) come first: 4 per w.
                if plate.repetition == 0 {
                    plates.push("validation".to_string());
                    return episode(env, &mut []);
                }
                plates.push(plate.label.clone());
                episode(env, &mut [&mut steps])
            },
            |_| {},
        )
        .unwrap();
    let validation = 4 * hil_paper::methods::QG_W_GRID.len();
    assert!(plates[..validation].iter().all(|p| p == "validation"));
    assert_eq!(plates[validation..], ["LinUCB", "AlwaysQuery", "LinUCB-QG"]);
    assert_eq!(
        steps.0,
        result.plates.iter().map(|p| p.n_steps).sum::<usize>()
    );
}
