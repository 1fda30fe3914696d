//! A plugin object whose destructor panics: the panic is caught inside the
//! plugin and handed to the host as an error naming the library, the type
//! and `drop` (what PLUGINS.md promises), for the host to report.
//!
//! Its own test binary: the host's list of destructor panics is global to
//! the process, and the other plugin tests drop panicking objects too.

use std::path::Path;

use hil_config::BuildContext;
use hil_conformance::cdylib::{build_cdylibs, cdylib_path};
use hil_core::HilError;
use hil_plugin::{self as plugin, Params};

#[test]
#[ignore = "e2e: needs a nested cargo build of plugin libraries; bash scripts/test runs it"]
fn every_kind_of_object_reports_a_destructor_panic_to_the_host() {
    let krate = "hil-test-plugin-panicky";
    let ws = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let lib = cdylib_path(&build_cdylibs(ws, &[krate]).unwrap(), krate);
    plugin::load(&lib).unwrap();
    let ctx = BuildContext::new(".", 0);
    let actions = hil_core::ActionSpace::new(["a", "b"]).unwrap();
    let task = hil_config::TaskContext::new(ctx.clone(), actions, 4);
    let p = Params::toml("panic_in = \"drop\"");
    let _lock = crate::common::destructor_panics_lock();
    assert!(plugin::take_destructor_panics().is_empty());

    drop(plugin::build_policy("panicky_policy", &p, &task).unwrap());
    drop(plugin::build_environment("panicky_env", &p, &ctx).unwrap());
    drop(plugin::build_workload_model("panicky_workload", &p, &ctx).unwrap());
    drop(plugin::build_query_channel("panicky_channel", &p, &task).unwrap());
    // An object that does not panic reports nothing.
    drop(plugin::build_policy("panicky_policy", &Params::empty(), &task).unwrap());

    let reported = plugin::take_destructor_panics();
    let names: Vec<String> = reported
        .iter()
        .map(|e| match e {
            HilError::Plugin { path, why } => {
                assert_eq!(path, &lib);
                assert!(why.contains("panicked in drop: boom in drop"), "{why}");
                why.split('`').nth(1).unwrap().to_string()
            }
            other => panic!("expected a plugin error, got {other:?}"),
        })
        .collect();
    assert_eq!(
        names,
        [
            "panicky_policy",
            "panicky_env",
            "panicky_workload",
            "panicky_channel"
        ]
    );
    // Taken once.
    assert!(plugin::take_destructor_panics().is_empty());
}
