//! A plugin claiming another hil-core version and other type layouts: hosts
//! must refuse it, naming both sides' values of each.

use hil_plugin::{ABI_VERSION, BuildFacts, FixedStr, Registrar};

fn register(r: &mut Registrar<'_>) {
    r.workload_model("never_registered", "", |_, _| unreachable!());
}

hil_plugin::__declare_plugin_with!(
    register,
    ABI_VERSION,
    BuildFacts {
        hil_core_version: FixedStr::new("0.0.1-mismatched"),
        interface_layout: 1,
        ..BuildFacts::current()
    }
);
