//! A plugin claiming another hil-core version: hosts must refuse it,
//! naming both versions.

use hil_core::plugin::{ABI_VERSION, BuildFacts, FixedStr, Registrar};

fn register(r: &mut Registrar<'_>) {
    r.workload_model("never_registered", "", |_, _| unreachable!());
}

hil_core::__declare_plugin_with!(
    register,
    ABI_VERSION,
    BuildFacts {
        hil_core_version: FixedStr::new("0.0.1-mismatched"),
        ..BuildFacts::current()
    }
);
