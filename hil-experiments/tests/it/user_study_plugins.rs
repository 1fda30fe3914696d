//! A study file naming a plugin type, exactly like a built-in one: the
//! `plugins` it lists are loaded before its components are read.

use std::path::Path;

use hil_conformance::cdylib::{build_cdylibs, cdylib_path};
use hil_experiments::user_study::UserStudyConfig;

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn a_plugin_channel_answers_the_study() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("hil-experiments sits in the workspace root");
    let krate = "hil-example-channel-noisy-expert";
    let dir = build_cdylibs(workspace, &[krate]).unwrap();
    let lib = cdylib_path(&dir, krate);
    let text = format!(
        r#"plugins = [{lib:?}]
repetitions = 1

[environment]
type = "food_replay"
foods = ["banana", "carrot"]
pretrain_foods = ["apple", "kiwi"]
items_per_episode = 2

[channel]
type = "noisy_expert"   # registered by the plugin
error = 0.2
"#,
        lib = lib.display().to_string()
    );
    let cfg = UserStudyConfig::parse(&text, Path::new("study.toml")).unwrap();
    let result = cfg.run(Path::new("."), |_| {}).unwrap();
    assert_eq!(result.plates.len(), 3);
    // AlwaysQuery asks at both items, through the plugin's channel.
    assert!(
        result
            .plates
            .iter()
            .any(|p| p.method == "AlwaysQuery" && p.n_q >= 2)
    );

    // A type nobody registered is an error at the `[channel]` table.
    let err = UserStudyConfig::parse(
        &text.replace("\"noisy_expert\"", "\"noisy_experts\""),
        Path::new("study.toml"),
    )
    .unwrap_err();
    assert!(
        err.field
            .as_deref()
            .is_some_and(|f| f.starts_with("channel")),
        "{err}"
    );
    assert_eq!(err.line, 11, "{err}");
}
