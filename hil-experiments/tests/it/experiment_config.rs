//! Experiment configs: typetag-named components, located errors, and a full
//! build-and-run through the session loop.

use std::path::Path;
use std::sync::Arc;

use hil_config::BuildContext;
use hil_config::TaskContext;
use hil_config::{EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig};
use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::channel::PerfectExpert;
use hil_core::{
    ActionSpace, ArmId, Choice, Environment, HilError, Policy, QueryChannel, QueryKind,
    WorkloadModel,
};
use hil_experiments::ExperimentConfig;
use serde::{Deserialize, Serialize};

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableEnvConfig {
    items: Vec<(String, Vec<f64>)>,
}

#[typetag::serde(name = "test_table")]
impl EnvironmentConfig for TableEnvConfig {
    fn build(&self, _ctx: &BuildContext) -> hil_core::Result<Box<dyn Environment>> {
        let items = self
            .items
            .iter()
            .map(|(l, p)| (l.as_str(), p.clone()))
            .collect();
        Ok(Box::new(TableEnv::new(
            ActionSpace::new(["A", "B", "C"])?,
            items,
        )?))
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct AskFirstConfig {
    /// Ask on the first attempt, then act with this arm.
    arm: usize,
}

#[typetag::serde(name = "test_ask_first")]
impl PolicyConfig for AskFirstConfig {
    fn build(&self, ctx: &TaskContext) -> hil_core::Result<Box<dyn Policy>> {
        let n = ctx.action_space().len();
        if self.arm >= n {
            return Err(HilError::invalid_parameter(
                "arm",
                self.arm,
                format!("must be below {n}"),
            ));
        }
        let dim = ctx.context_dim();
        Ok(Box::new(ScriptedPolicy::new(
            n,
            dim,
            vec![
                Choice::Query {
                    kind: QueryKind::default(),
                    fallback: ArmId(self.arm),
                },
                Choice::Act {
                    arm: ArmId(self.arm),
                },
            ],
        )))
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CountingConfig {
    increment: f64,
}

#[typetag::serde(name = "test_counting")]
impl WorkloadModelConfig for CountingConfig {
    fn build(&self, _ctx: &BuildContext) -> hil_core::Result<Arc<dyn WorkloadModel>> {
        Ok(Arc::new(CountingWorkload::new(self.increment)))
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct OracleConfig {}

#[typetag::serde(name = "test_oracle")]
impl QueryChannelConfig for OracleConfig {
    fn build(&self, _ctx: &TaskContext) -> hil_core::Result<Box<dyn QueryChannel>> {
        Ok(Box::new(PerfectExpert::default()))
    }
}

const GOOD: &str = r#"
seed = 3
episodes = 2

[session]
n_att = 4
wl0 = 0.4

[environment]
type = "test_table"
items = [["apple", [0.2, 0.9, 0.5]], ["kiwi", [0.7, 0.1, 0.1]]]

[policy]
type = "test_ask_first"
arm = 2

[workload]
type = "test_counting"
increment = 0.05

[channel]
type = "test_oracle"
"#;

fn parse(text: &str) -> Result<ExperimentConfig, hil_core::ConfigError> {
    ExperimentConfig::parse(text, Path::new("exp.toml"))
}

#[test]
fn a_good_config_builds_and_runs() {
    let cfg = parse(GOOD).unwrap();
    assert_eq!(cfg.session.n_att, 4);
    let mut exp = cfg.build(Path::new(".")).unwrap();
    let summary = exp.run(&mut [], |_, _| {}).unwrap();
    assert_eq!(summary.episodes.len(), 2);
    // The scripted policy asks once, at the very first attempt, then acts.
    assert_eq!(summary.episodes[0].n_q, 1);
    assert_eq!(summary.episodes[1].n_q, 0);
    for m in &summary.episodes {
        assert!((m.delta_wl - 0.05 * m.n_q as f64).abs() < 1e-12);
    }
}

#[test]
fn misspelt_field_names_file_line_and_field() {
    let text = GOOD.replace("increment = 0.05", "incremnt = 0.05");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("workload.incremnt"), "{e}");
    assert_eq!(e.line, 19, "{e}");
    let msg = e.to_string();
    assert!(msg.starts_with("exp.toml:19:"), "{msg}");
    assert!(msg.contains("unknown field `incremnt`"), "{msg}");
}

#[test]
fn misspelt_top_level_and_session_fields() {
    let e = parse(&GOOD.replace("episodes = 2", "episode = 2")).unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (3, Some("episode")), "{e}");
    let e = parse(&GOOD.replace("n_att = 4", "n_atts = 4")).unwrap_err();
    assert_eq!(
        (e.line, e.field.as_deref()),
        (6, Some("session.n_atts")),
        "{e}"
    );
}

#[test]
fn unknown_type_name_is_reported() {
    let text = GOOD.replace("\"test_ask_first\"", "\"linucb_qgg\"");
    let e = parse(&text).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("linucb_qgg"), "{msg}");
    assert_eq!(e.field.as_deref(), Some("policy.type"), "{msg}");
    assert_eq!(e.line, 14, "{msg}");
}

#[test]
fn wrong_value_type_names_the_field() {
    let e = parse(&GOOD.replace("n_att = 4", "n_att = \"four\"")).unwrap_err();
    assert_eq!(
        (e.line, e.field.as_deref()),
        (6, Some("session.n_att")),
        "{e}"
    );
    assert!(e.to_string().contains("invalid type"), "{e}");
    let e = parse(&GOOD.replace("arm = 2", "arm = \"two\"")).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.arm"), "{e}");
    assert_eq!(e.line, 15, "{e}");
}

#[test]
fn invalid_values_are_reported_at_their_key() {
    let text = GOOD.replace("wl0 = 0.4", "wl0 = 1.5");
    let e = parse(&text).unwrap_err();
    let line = text.lines().position(|l| l.starts_with("wl0")).unwrap() + 1;
    assert_eq!(
        (e.line, e.field.as_deref()),
        (line, Some("session.wl0")),
        "{e}"
    );
    let e = parse(&GOOD.replace("episodes = 2", "episodes = 0")).unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (3, Some("episodes")), "{e}");
}

#[test]
fn missing_section_is_reported() {
    let text = GOOD.replace("[channel]\ntype = \"test_oracle\"\n", "");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("channel"), "{e}");
}

#[test]
fn missing_file_is_an_io_error() {
    let e = ExperimentConfig::load(Path::new("/nonexistent/exp.toml")).unwrap_err();
    assert!(
        matches!(e, hil_core::HilError::Io { ref path, .. } if path == Path::new("/nonexistent/exp.toml")),
        "{e:?}"
    );
}

/// Errors found only in building a component (an unknown food or
/// pretraining food, a bundled model that does not exist, a dataset file
/// that cannot be read) name the config file, line and key.
#[test]
fn build_errors_are_located_in_the_config() {
    let dir = std::env::temp_dir().join(format!("hil-build-located-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let base = r#"seed = 1
episodes = 1

[environment]
type = "food_replay"
foods = ["banana", "carrot"]
pretrain_foods = ["apple", "kiwi"]

[policy]
type = "linucb"
alpha = 0.5

[workload]
type = "bundled"
name = "f2_sim"

[channel]
type = "simulated_expert"
"#;
    let cases = [
        ("\"carrot\"]", "\"mango\"]", 6, "environment.foods"),
        ("\"kiwi\"]", "\"durian\"]", 7, "environment.pretrain_foods"),
        ("\"f2_sim\"", "\"f9_nope\"", 15, "workload.name"),
        (
            "type = \"food_replay\"",
            "type = \"food_replay\"\ndataset = \"/dev/zero\"",
            6,
            "environment.dataset",
        ),
    ];
    for (from, to, line, field) in cases {
        let path = dir.join("exp.toml");
        std::fs::write(&path, base.replacen(from, to, 1)).unwrap();
        match hil_experiments::run::Run::from_config(&path, None) {
            Err(HilError::Config(e)) => {
                assert_eq!(
                    (e.path.as_path(), e.line, e.field.as_deref()),
                    (path.as_path(), line, Some(field)),
                    "{e}"
                );
            }
            Err(other) => panic!("{field}: unlocated: {other}"),
            Ok(_) => panic!("{field}: accepted"),
        }
    }
}
