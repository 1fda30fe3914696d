//! Rust values to plain Python data and back, through their serde form
//! (JSON), so that every result shape has one definition: the Rust type's.

use std::sync::Arc;

use hil_core::{Context, HilError};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyModule;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::errors::IntoPy;

/// `value`'s serde form as plain Python data (dicts, lists, numbers, str).
pub(crate) fn to_py<T: Serialize + ?Sized>(
    py: Python<'_>,
    value: &T,
    what: &str,
) -> PyResult<Py<PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| HilError::serde(what, e))
        .py_err()?;
    let json = PyModule::import(py, "json")?;
    Ok(json.call_method1("loads", (text,))?.unbind())
}

/// Plain Python data (anything `json.dumps` accepts) as a `T`, through its
/// serde form; an error names `what`.
pub(crate) fn from_py<T: DeserializeOwned>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    let text = json_text(obj)?;
    serde_json::from_str(&text)
        .map_err(|e| HilError::serde(what, e))
        .py_err()
}

/// `value` as JSON text (what crosses to Python as a plain string, e.g.
/// between `hil.sweep`'s processes); an error names `what`.
pub(crate) fn to_json<T: Serialize + ?Sized>(what: &str, value: &T) -> PyResult<String> {
    serde_json::to_string(value)
        .map_err(|e| HilError::serde(what, e))
        .py_err()
}

/// JSON text as a `T`; an error names `what`.
pub(crate) fn from_json<T: DeserializeOwned>(what: &str, json: &str) -> PyResult<T> {
    serde_json::from_str(json)
        .map_err(|e| HilError::serde(what, e))
        .py_err()
}

/// `json.dumps(obj)`.
pub(crate) fn json_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    let json = PyModule::import(obj.py(), "json")?;
    json.call_method1("dumps", (obj,))?.extract()
}

/// A context from a 1-d float64 array: one copy, straight into the
/// context's shared buffer (hil's policies may keep a context, so it cannot
/// borrow NumPy's memory), checked once by `Context::new`.
pub(crate) fn context(array: &Bound<'_, PyArray1<f64>>) -> PyResult<Context> {
    Context::new(values(array)).py_err()
}

/// The entries of a 1-d float64 array in a new shared buffer (one copy).
///
/// The array is read without rust-numpy's borrow tracking (a
/// `PyReadonlyArray`), which costs more than the copy itself on a call whose
/// caches are cold (hil-py/README.md, "Crossing into Rust").
pub(crate) fn values(array: &Bound<'_, PyArray1<f64>>) -> Arc<[f64]> {
    // SAFETY: the values are copied at once with the GIL held and no
    // reference into NumPy's memory outlives this call: the reasoning of
    // rust-numpy's own safe `to_vec`, which reads through `as_slice` too.
    match unsafe { array.as_slice() } {
        Ok(values) => Arc::from(values),
        // Not contiguous (a strided view): gather the entries.
        Err(_) => array.to_owned_array().iter().copied().collect(),
    }
}

/// Copies a contiguous `array` into `buf` (of its length); false if the
/// array is not contiguous.
pub(crate) fn copy_context(array: &Bound<'_, PyArray1<f64>>, buf: &mut [f64]) -> bool {
    // SAFETY: as in `context`.
    match unsafe { array.as_slice() } {
        Ok(values) => {
            buf.copy_from_slice(values);
            true
        }
        Err(_) => false,
    }
}

/// A context as a new 1-d float array.
pub(crate) fn array<'py>(py: Python<'py>, context: &Context) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, context.as_slice())
}

/// Plain Python data as a TOML value, the form component configs are
/// read in (unlike JSON, TOML holds NaN and infinities, so a bad float
/// reaches the parameter's own validation and its error names it).
pub(crate) fn to_toml(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
    if obj.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(obj.extract()?));
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(obj.extract()?));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            let value = to_toml(&v, &format!("{what}.{key}"))?;
            t.insert(key, value);
        }
        return Ok(toml::Value::Table(t));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj
            .try_iter()?
            .map(|v| to_toml(&v?, what))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    // NumPy scalars and arrays: through their Python form.
    if obj.hasattr("tolist")? {
        return to_toml(&obj.call_method0("tolist")?, what);
    }
    Err(crate::errors::to_py_err(HilError::invalid_input(
        what,
        format!(
            "a {} cannot be a config value (use bool, int, float, str, list or dict)",
            obj.get_type().name()?
        ),
    )))
}
