//! Every count, size and window of an experiment config is checked against
//! `hil_config::limits` when the file is loaded, and a bad parameter
//! of any built-in component is a `ConfigError` naming the file, line and
//! field, with the offending value shortened (issue 14, items 1 and 10).

use std::path::Path;

use hil_config::limits;
use hil_core::error::ECHO_CHARS;
use hil_core::{ConfigError, HilError};
use hil_experiments::ExperimentConfig;

/// A valid experiment of demo components; `{episodes}` etc. are replaced.
const DEMO: &str = r#"seed = 3
episodes = EPISODES

[session]
n_att = N_ATT

[environment]
type = "demo_plate"
foods = FOODS
repeat = REPEAT

[policy]
type = "demo_learner"
query_probability = 0.5

[workload]
type = "demo_counting"
increment = 0.05
window = WINDOW

[channel]
type = "simulated_expert"
response_time = { median_s = 4.0, sigma = SIGMA }
"#;

/// A valid experiment of the paper's components.
const PAPER: &str = r#"seed = 1

[environment]
type = "food_replay"
foods = ["banana", "carrot"]
items_per_episode = ITEMS

[policy]
type = "linucb_qg"
alpha = ALPHA
w = 0.2

[workload]
type = "bundled"
name = "f1_sim"

[channel]
type = "simulated_expert"
"#;

fn demo(replace: &[(&str, &str)]) -> String {
    fill(
        DEMO,
        &[
            ("EPISODES", "2"),
            ("N_ATT", "3"),
            ("FOODS", r#"["banana", "grape"]"#),
            ("REPEAT", "2"),
            ("WINDOW", "10"),
            ("SIGMA", "0.5"),
        ],
        replace,
    )
}

fn paper(replace: &[(&str, &str)]) -> String {
    fill(PAPER, &[("ITEMS", "5"), ("ALPHA", "0.5")], replace)
}

fn fill(template: &str, defaults: &[(&str, &str)], replace: &[(&str, &str)]) -> String {
    let mut text = template.to_string();
    for (key, default) in defaults {
        let value = replace
            .iter()
            .find(|(k, _)| k == key)
            .map_or(*default, |(_, v)| v);
        text = text.replace(key, value);
    }
    text
}

/// The 1-based line of `text` on which `key = ` is written.
fn line_of(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| l.trim_start().starts_with(&format!("{key} =")))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("no `{key}` in\n{text}"))
}

/// Parses `text`, which must be refused, and checks where.
fn refused(text: &str, field: &str, key: &str) -> ConfigError {
    let path = Path::new("dir/experiment.toml");
    let e = ExperimentConfig::parse(text, path).expect_err("must be refused");
    assert_eq!(e.path, path, "{e}");
    assert_eq!(e.field.as_deref(), Some(field), "{e}");
    assert_eq!(e.line, line_of(text, key), "{e}");
    // Whatever was echoed, the message stays short.
    assert!(
        e.to_string().len() < 8 * ECHO_CHARS,
        "{} bytes",
        e.to_string().len()
    );
    e
}

#[test]
fn the_templates_are_valid() {
    ExperimentConfig::parse(&demo(&[]), Path::new("demo.toml")).unwrap();
    ExperimentConfig::parse(&paper(&[]), Path::new("paper.toml")).unwrap();
    // At the limits, still valid (nothing is allocated at load time).
    let max = limits::EPISODES.to_string();
    ExperimentConfig::parse(&demo(&[("EPISODES", &max)]), Path::new("demo.toml")).unwrap();
    let max = limits::ITEMS_PER_EPISODE.to_string();
    ExperimentConfig::parse(&paper(&[("ITEMS", &max)]), Path::new("paper.toml")).unwrap();
}

#[test]
fn huge_episode_counts_are_located_errors() {
    for n in ["9223372036854775807", "4294967296", "100001", "0"] {
        refused(&demo(&[("EPISODES", n)]), "episodes", "episodes");
    }
}

#[test]
fn huge_items_per_episode_are_located_errors() {
    for n in [
        "9223372036854775807",
        "4294967296",
        "1000000000000",
        "1e12",
        "0",
    ] {
        refused(
            &paper(&[("ITEMS", n)]),
            "environment.items_per_episode",
            "items_per_episode",
        );
    }
}

#[test]
fn a_huge_demo_plate_is_a_located_error() {
    for n in ["4294967296", "9223372036854775807", "50001", "0"] {
        refused(&demo(&[("REPEAT", n)]), "environment.repeat", "repeat");
    }
    // foods × repeat is what is bounded.
    let text = demo(&[("REPEAT", &limits::ITEMS_PER_EPISODE.to_string())]);
    refused(&text, "environment.repeat", "repeat");
}

#[test]
fn huge_windows_and_session_counts_are_located_errors() {
    refused(
        &demo(&[("WINDOW", "1000000000000")]),
        "workload.window",
        "window",
    );
    refused(&demo(&[("WINDOW", "0")]), "workload.window", "window");
    refused(&demo(&[("N_ATT", "4294967295")]), "session.n_att", "n_att");
    let text = demo(&[("N_ATT", "3\nmax_items = 9223372036854775807")]);
    refused(&text, "session.max_items", "max_items");
}

#[test]
fn non_finite_parameters_name_the_file_line_and_field() {
    refused(&paper(&[("ALPHA", "inf")]), "policy.alpha", "alpha");
    refused(&paper(&[("ALPHA", "nan")]), "policy.alpha", "alpha");
    // A nested table's parameter.
    let text = paper(&[]).replace(
        "w = 0.2\n",
        "w = 0.2\n[policy.estimator]\ncrossover = nan\n",
    );
    refused(&text, "policy.estimator.crossover", "crossover");
    // Every built-in policy, with its own fields.
    for ty in hil_policies::POLICY_TYPES {
        let mut table = format!("type = \"{ty}\"\nalpha = inf\n");
        for (key, value) in hil_policies::example_fields(ty).unwrap() {
            table.push_str(&format!("{key} = {value}\n"));
        }
        let text = paper(&[]).replace("type = \"linucb_qg\"\nalpha = 0.5\nw = 0.2\n", &table);
        assert!(text.contains(ty), "{text}");
        refused(&text, "policy.alpha", "alpha");
    }
    // A response time's spread inside an inline table.
    let too_wide = (2.0 * hil_channels::simulated::MAX_SIGMA).to_string();
    for sigma in ["1e308", "inf", too_wide.as_str()] {
        refused(
            &demo(&[("SIGMA", sigma)]),
            "channel.response_time.sigma",
            "response_time",
        );
    }
    // An inline component table.
    let text = paper(&[]).replace("[policy]\ntype = \"linucb_qg\"\nalpha = 0.5\nw = 0.2\n", "");
    let text = format!("policy = {{ type = \"linucb_qg\", alpha = inf, w = 0.2 }}\n{text}");
    refused(&text, "policy.alpha", "policy");
}

#[test]
fn a_100_kb_value_is_echoed_shortly() {
    // 100 KB of digits: a float that overflows to infinity.
    let huge = format!("1{}.0", "0".repeat(100_000));
    let e = refused(&paper(&[("ALPHA", &huge)]), "policy.alpha", "alpha");
    assert!(e.message.len() < 4 * ECHO_CHARS, "{}", e.message);
    // A 100 KB food name.
    let name = "x".repeat(100_000);
    let e = refused(
        &demo(&[("FOODS", &format!("[\"{name}\"]"))]),
        "environment.foods",
        "foods",
    );
    assert!(e.message.contains("bytes"), "{}", e.message);
    // A 100 KB string where a number belongs: serde quotes it.
    let e = refused(
        &paper(&[("ALPHA", &format!("\"{name}\""))]),
        "policy.alpha",
        "alpha",
    );
    assert!(e.message.contains("expected"), "{}", e.message);
}

#[test]
fn loading_a_file_names_it() {
    let dir = std::env::temp_dir().join(format!("hil-config-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("experiment.toml");
    let text = demo(&[("REPEAT", "4294967296")]);
    std::fs::write(&path, &text).unwrap();
    let e = ExperimentConfig::load(&path).unwrap_err();
    match e {
        HilError::Config(c) => {
            assert_eq!(c.path, path);
            assert_eq!(c.field.as_deref(), Some("environment.repeat"));
            assert_eq!(c.line, line_of(&text, "repeat"));
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn parameter_errors_keep_their_variant_outside_configs() {
    // Built directly (no file), the same check is an InvalidParameter.
    let e = hil_envs::demo_plate::DemoPlate::new(&["banana".into()], usize::MAX).unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, .. } if name == "repeat"),
        "{e}"
    );
    let ds = hil_envs::bundled_dataset().unwrap();
    let e = hil_envs::DatasetReplayEnv::new(ds, &["banana".into()], usize::MAX).unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, .. } if name == "items_per_episode"),
        "{e}"
    );
    let long = "y".repeat(100_000);
    let e = HilError::invalid_parameter("foods", &long, "unknown food");
    match e {
        HilError::InvalidParameter { value, .. } => assert!(value.len() < 2 * ECHO_CHARS),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_synthetic_study_with_huge_counts_is_refused_before_it_is_generated() {
    use hil_workload::synth::SynthConfig;
    let huge = SynthConfig {
        n_no_limitation: usize::MAX,
        ..SynthConfig::default()
    };
    let e = huge.generate(1).unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, .. } if name == "n_no_limitation"),
        "{e}"
    );
    let slow = SynthConfig {
        survey_time_median_s: f64::INFINITY,
        ..SynthConfig::small(2, 1)
    };
    assert!(matches!(
        slow.validate(),
        Err(HilError::InvalidParameter { name, .. }) if name == "survey_time_median_s"
    ));
    SynthConfig::default().validate().unwrap();
}

#[test]
fn an_experiment_built_in_code_checks_its_episodes_before_allocating() {
    let cfg = ExperimentConfig::parse(&demo(&[]), Path::new("demo.toml")).unwrap();
    let mut experiment = cfg.build(Path::new(".")).unwrap();
    experiment.episodes = usize::MAX;
    let e = experiment.run(&mut [], |_, _| {}).unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, .. } if name == "episodes"),
        "{e}"
    );
}
