//! A plugin declaring an ABI version no host speaks: hosts must refuse it
//! before reading anything else, naming both versions.

use hil_plugin::{BuildFacts, Registrar};

fn register(r: &mut Registrar<'_>) {
    // Never called: the handshake fails first.
    r.workload_model("never_registered", "", |_, _| unreachable!());
}

hil_plugin::__declare_plugin_with!(register, 999, BuildFacts::current());
