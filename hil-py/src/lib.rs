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
//! - [`pretrain`]: a Python policy's pretraining on the environment's data;
//! - [`session`]: the session loop with its record and resume;
//! - [`reproduce`]: the paper's simulated protocol;
//! - [`user_study`]: the paper's user-study protocol on any environment;
//! - [`interrupt`]: long work that Ctrl-C stops and that reports progress;
//! - [`workload`]: the study loader, fitting and model selection;
//! - [`testing`]: the conformance suites.

use pyo3::prelude::*;
// Links `[channel] type = "speech"` (hil.channels.speech).
use hil_speech as _;

mod components;
mod convert;
mod errors;
mod gym;
mod interrupt;
mod pretrain;
mod pycomponents;
mod registry;
mod reproduce;
mod session;
mod sweep;
mod testing;
mod user_study;
mod workload;

/// The native module. The Python package re-exports its public names.
#[pymodule]
fn _hil(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Every built-in component type is linked through hil-experiments
    // (`hil_experiments::builtin`); nothing to call. Whether this build can
    // run the Kinova environment: the `kinova` feature turns on MuJoCo
    // physics (without it the type parses but refuses to build).
    m.add("KINOVA", cfg!(feature = "kinova"))?;
    // Whether `QueryChannel("speech", ...)` can hear: the `speech` feature
    // links the recognizer (without it the type parses but refuses to
    // build, naming the feature). Naming the crate links its config type.
    m.add("SPEECH", cfg!(feature = "speech"))?;
    // Python components run on the job runner's workers (rayon's global
    // pool by default): give them a main thread's stack, as
    // `hil_jobs::Runner::new` does, before anything starts that pool
    // (NumPy's threaded OpenBLAS overflows rayon's default 2 MiB). If the
    // pool exists already (a host built it), it is kept as it is.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(hil_jobs::WORKER_STACK_BYTES)
        .build_global();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The UCB weight α of the paper's methods (hil's choice; the paper does not state it).
    m.add("PAPER_ALPHA", hil_paper::methods::ALPHA)?;
    errors::register(m)?;
    m.add_function(wrap_pyfunction!(convert::plain_json, m)?)?;
    components::register(m)?;
    registry::register_module(m)?;
    session::register(m)?;
    reproduce::register(m)?;
    workload::register(m)?;
    testing::register(m)?;
    gym::register(m)?;
    sweep::register(m)?;
    user_study::register(m)?;
    Ok(())
}
