//! Python bindings of hil: the native module `hil._hil` behind the `hil`
//! Python package (`hil-py/python/hil`).
//!
//! Everything heavy runs with the GIL released; contexts and results cross
//! the boundary as NumPy arrays, results and records as plain Python data
//! made from the Rust types' serde form ([`convert`]).
//!
//! - [`errors`]: one exception class per hil error kind;
//! - [`components`]: hil's policies, environments, query channels and
//!   workload models, built from configs;
//! - [`pycomponents`]: Python objects serving as those four traits;
//! - [`registry`]: Python factories as named component types;
//! - [`session`]: the session loop with its record and resume;
//! - [`reproduce`]: the paper's simulated protocol;
//! - [`workload`]: the study loader, fitting and model selection;
//! - [`testing`]: the conformance suites.

use pyo3::prelude::*;

mod components;
mod convert;
mod errors;
mod gym;
mod pycomponents;
mod registry;
mod reproduce;
mod session;
mod sweep;
mod testing;
mod workload;

/// The native module. The Python package re-exports its public names.
#[pymodule]
fn _hil(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Keep the built-in component crates (and their typetag registrations)
    // linked: Python names their types only in configs.
    hil_policies::link();
    hil_workload::link();
    hil_envs::link();
    hil_channels::link();
    #[cfg(feature = "kinova")]
    hil_kinova_mujoco::link();
    // Whether this build has the Kinova environment: whether its config
    // type parses (nothing is built, MuJoCo is not called).
    let mut probe = toml::Table::new();
    probe.insert("type".into(), "kinova_feeding".into());
    let kinova = components::environment_config(toml::Value::Table(probe)).is_ok();
    m.add("KINOVA", kinova)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The UCB weight α of the paper's methods (hil's choice; the paper does not state it).
    m.add("PAPER_ALPHA", hil_experiments::method::PAPER_ALPHA)?;
    errors::register(m)?;
    components::register(m)?;
    registry::register_module(m)?;
    session::register(m)?;
    reproduce::register(m)?;
    workload::register(m)?;
    testing::register(m)?;
    gym::register(m)?;
    sweep::register(m)?;
    Ok(())
}
