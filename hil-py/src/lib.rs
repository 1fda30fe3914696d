//! Python bindings of hil: the native module `hil._hil` behind the `hil`
//! Python package (`hil-py/python/hil`).
//!
//! Everything heavy runs with the GIL released; contexts and results cross
//! the boundary as NumPy arrays.

use pyo3::prelude::*;

mod errors;
mod gym;
mod sweep;

/// The native module. The Python package re-exports its public names.
#[pymodule]
fn _hil(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    gym::register(m)?;
    sweep::register(m)?;
    Ok(())
}
