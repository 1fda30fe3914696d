//! hil's errors as Python exceptions.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    hil,
    HilError,
    PyException,
    "Base class of every error raised by hil's native code."
);

/// Converts a hil error into the Python exception that represents it.
#[allow(dead_code)] // remove once a binding uses it
pub(crate) fn to_py_err(error: hil_core::HilError) -> PyErr {
    HilError::new_err(error.to_string())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("HilError", m.py().get_type::<HilError>())
}
