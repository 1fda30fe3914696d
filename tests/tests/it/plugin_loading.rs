//! Loading plugins: every refusal is a clear error naming the file, and
//! loading is idempotent.

use crate::common;
use hil_config::TaskContext;

use std::path::Path;

use common::{lib, scratch};
use hil_config::BuildContext;
use hil_core::{ActionSpace, HilError};
use hil_plugin::{self as plugin, ComponentKind, Params};

fn ctx() -> BuildContext {
    BuildContext::new(".", 5)
}

/// What policies and channels are built from: six actions, 4-d contexts.
fn task() -> TaskContext {
    let actions = ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap();
    TaskContext::new(ctx(), actions, 4)
}

fn why(e: &HilError) -> String {
    match e {
        HilError::Plugin { why, .. } => why.clone(),
        other => panic!("expected a plugin error, got {other:?}"),
    }
}

#[test]
fn a_missing_file_is_named() {
    let e = plugin::load(Path::new("no/such/libthing.so")).unwrap_err();
    assert!(
        matches!(e, hil_core::HilError::Plugin { ref path, .. } if path == Path::new("no/such/libthing.so")),
        "{e:?}"
    );
    assert_eq!(why(&e), "no such file");
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn a_library_without_a_declaration_is_not_a_plugin() {
    let e = plugin::load(&lib("hil-test-plugin-not-a-plugin")).unwrap_err();
    assert!(why(&e).starts_with("not a hil plugin"), "{e}");
    assert!(why(&e).contains("HIL_PLUGIN_DECLARATION"), "{e}");
}

#[test]
fn a_file_that_is_not_a_library_is_refused() {
    let dir = scratch("garbage");
    let f = dir.join("libgarbage.so");
    std::fs::write(&f, b"this is not an ELF file").unwrap();
    let e = plugin::load(&f).unwrap_err();
    assert!(
        why(&e).contains("cannot be loaded as a shared library"),
        "{e}"
    );
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn an_abi_mismatch_names_both_versions() {
    let e = plugin::load(&lib("hil-test-plugin-mismatched-abi")).unwrap_err();
    let w = why(&e);
    assert!(w.contains("ABI version 999"), "{w}");
    assert!(
        w.contains(&format!("ABI version {}", plugin::ABI_VERSION)),
        "{w}"
    );
    assert!(!plugin::is_registered(
        ComponentKind::WorkloadModel,
        "never_registered"
    ));
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn a_hil_core_version_mismatch_names_both_versions() {
    let e = plugin::load(&lib("hil-test-plugin-mismatched-version")).unwrap_err();
    let w = why(&e);
    assert!(w.contains("version mismatch"), "{w}");
    assert!(w.contains("plugin \"0.0.1-mismatched\""), "{w}");
    assert!(
        w.contains(&format!("host \"{}\"", env!("CARGO_PKG_VERSION"))),
        "{w}"
    );
    assert!(
        w.contains(&format!(
            "interface layout: plugin \"0000000000000001\", host \"{:016x}\"",
            plugin::interface_layout()
        )),
        "{w}"
    );
    // The facts that agree are not listed.
    assert!(!w.contains("rustc version"), "{w}");
    assert!(!plugin::is_registered(
        ComponentKind::WorkloadModel,
        "never_registered"
    ));
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn loading_the_same_library_twice_is_harmless() {
    let path = lib("hil-example-env-grasp");
    let a = plugin::load(&path).unwrap();
    // A different spelling of the same file.
    let dir = path.parent().unwrap();
    let other = dir.join(".").join(path.file_name().unwrap());
    let b = plugin::load(&other).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.components.len(), 1);
    assert_eq!(a.components[0].name, "grasp_choice");
    let n = plugin::libraries()
        .iter()
        .filter(|l| l.path == a.path)
        .count();
    assert_eq!(n, 1);
    let env = plugin::build_environment("grasp_choice", &Params::empty(), &ctx()).unwrap();
    assert_eq!(env.action_space().len(), 5);
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn a_duplicate_name_is_refused_naming_the_first_library() {
    let original = lib("hil-example-workload-fatigue");
    let first = plugin::load(&original).unwrap();
    let dir = scratch("duplicate");
    let copy = dir.join(original.file_name().unwrap());
    std::fs::copy(&original, &copy).unwrap();
    let e = plugin::load(&copy).unwrap_err();
    let w = why(&e);
    assert!(w.contains("duplicate workload model name `fatigue`"), "{w}");
    assert!(w.contains(&first.path.display().to_string()), "{w}");
    // The first registration still works.
    plugin::build_workload_model("fatigue", &Params::empty(), &ctx()).unwrap();
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn an_unknown_name_lists_the_closest_registered_names() {
    plugin::load(&lib("hil-example-policy-thompson")).unwrap();
    let e = plugin::build_policy("linear_thomson", &Params::empty(), &task())
        .err()
        .unwrap();
    let msg = e.to_string();
    assert!(msg.contains("`linear_thomson`"), "{msg}");
    assert!(msg.contains("closest: `linear_thompson`"), "{msg}");
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn a_factory_rejecting_its_parameters_says_which_and_why() {
    let info = plugin::load(&lib("hil-example-policy-thompson")).unwrap();
    let e = plugin::build_policy("linear_thompson", &Params::toml("v = -1.0"), &task())
        .err()
        .unwrap();
    let msg = e.to_string();
    assert!(msg.contains(&info.path.display().to_string()), "{msg}");
    assert!(
        msg.contains("policy `linear_thompson` could not be built from its parameters"),
        "{msg}"
    );
    assert!(msg.contains("`v` = -1"), "{msg}");
    let e = plugin::build_policy(
        "linear_thompson",
        &Params::json(r#"{"sample": 3}"#),
        &task(),
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("unknown field `sample`"), "{e}");
}

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn list_reports_the_build_facts() {
    let info = plugin::load(&lib("hil-example-channel-noisy-expert")).unwrap();
    assert_eq!(info.abi_version, plugin::ABI_VERSION);
    let facts: Vec<&str> = info.build.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        facts,
        [
            "hil-core version",
            "rustc version",
            "target",
            "build profile",
            "interface layout"
        ]
    );
    assert_eq!(info.components[0].kind, ComponentKind::QueryChannel);
}
