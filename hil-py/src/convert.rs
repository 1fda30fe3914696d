//! Rust values to plain Python data and back, through their serde form
//! (JSON), so that every result shape has one definition: the Rust type's.

use std::sync::Arc;

use hil_core::{Context, HilError};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyModule;
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

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

/// Plain Python data (dicts, lists, tuples, numbers, str, None, NumPy
/// scalars and arrays) as a `T`, through its serde form; an error names
/// `what` (and the key at fault, see [`to_value`]).
pub(crate) fn from_py<T: DeserializeOwned>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    serde_json::from_value(to_value(obj, what)?)
        .map_err(|e| HilError::serde(what, e))
        .py_err()
}

/// Plain Python data as a JSON value, exactly: every int that JSON's
/// numbers hold (i64 or u64) stays that int, and anything that would not
/// come back as it went in (an int of more bits, e.g. a NumPy PCG64
/// state, or a NaN / infinite float) is refused with an error naming its
/// key (`what.key[2].key`), never turned silently into a float.
pub(crate) fn to_value(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    value_at(obj, what, 0)
}

/// Deepest nesting of plain data read from Python: far beyond any config
/// or result, and low enough that a list holding itself, or an object
/// whose `tolist()` returns itself, is an error naming its key instead of
/// a stack overflow that kills the interpreter.
const MAX_DEPTH: usize = 128;

/// The error for data nested past [`MAX_DEPTH`] at `what`, if `depth` is.
fn check_depth(what: &str, depth: usize) -> PyResult<()> {
    if depth <= MAX_DEPTH {
        return Ok(());
    }
    Err(crate::errors::to_py_err(HilError::invalid_input(
        what,
        format!("nested more than {MAX_DEPTH} levels deep (does a list or dict contain itself?)"),
    )))
}

fn value_at(obj: &Bound<'_, PyAny>, what: &str, depth: usize) -> PyResult<Value> {
    use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
    check_depth(what, depth)?;
    let refuse = |why: String| Err(crate::errors::to_py_err(HilError::invalid_input(what, why)));
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(i.into());
        }
        if let Ok(u) = obj.extract::<u64>() {
            return Ok(u.into());
        }
        return refuse(format!(
            "the int {obj} has more than 64 bits, which hil's JSON cannot hold exactly; \
             store it as a string (str(n)) and convert it back (int(s))"
        ));
    }
    if obj.is_instance_of::<PyFloat>() {
        let x: f64 = obj.extract()?;
        return match serde_json::Number::from_f64(x) {
            Some(n) => Ok(Value::Number(n)),
            None => refuse(format!("{x} is not a finite number")),
        };
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in d.iter() {
            let Ok(key) = k.extract::<String>() else {
                return refuse(format!("the key {k} is not a str (JSON keys are strings)"));
            };
            let value = value_at(&v, &format!("{what}.{key}"), depth + 1)?;
            map.insert(key, value);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj
            .try_iter()?
            .enumerate()
            .map(|(i, v)| value_at(&v?, &format!("{what}[{i}]"), depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(Value::Array(items));
    }
    // NumPy scalars and arrays: through their Python form.
    if obj.hasattr("tolist")? {
        return value_at(&obj.call_method0("tolist")?, what, depth + 1);
    }
    refuse(format!(
        "a {} is not plain data (use None, bool, int, float, str, list or dict)",
        obj.get_type().name()?
    ))
}

/// Plain Python data as JSON text, for the package's own Python code to
/// hand a dict to a function that takes JSON: a NaN or infinite float
/// anywhere is an `InvalidInputError` naming its key (`what.session.wl0`),
/// where `json.dumps` would write a bare `NaN` that fails to parse at a
/// column.
#[pyfunction]
pub(crate) fn plain_json(value: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    to_json(what, &to_value(value, what)?)
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

/// A context argument: a 1-d float64 NumPy array as it is (the fast path,
/// no conversion), or anything NumPy reads as a 1-d array of numbers (a
/// list, a float32 or int array), converted once; anything else is an
/// error naming `context` with what was given.
pub(crate) struct ContextArg<'py>(pub(crate) Bound<'py, PyArray1<f64>>);

impl<'a, 'py> FromPyObject<'a, 'py> for ContextArg<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(a) = obj.cast::<PyArray1<f64>>() {
            return Ok(Self(a.to_owned()));
        }
        let obj = obj.to_owned();
        let refuse =
            |why: String| crate::errors::to_py_err(HilError::invalid_input("context", why));
        let numpy = PyModule::import(obj.py(), "numpy")?;
        let array = numpy
            .call_method1("asarray", (&obj, "float64"))
            .map_err(|e| {
                let given = obj
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default();
                refuse(format!("a {given} is not a 1-d array of numbers ({e})"))
            })?;
        let shape = array.getattr("shape")?;
        array
            .cast_into::<PyArray1<f64>>()
            .map(Self)
            .map_err(|_| refuse(format!("must be a 1-d array, got one of shape {shape}")))
    }
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
    toml_of(obj, what, false, 0)
}

/// Plain Python data that may hold NaN or infinities (a Python policy's
/// decision and diagnostics) as a value serde reads a `T` from: through
/// TOML's data model, which keeps non-finite floats intact, so they reach
/// the check that names them (the session's, or the conformance suite's
/// `finite diagnostics`) instead of failing as unparsable JSON. A dict
/// entry that is None is left out (an absent `Option` field is None).
pub(crate) fn from_py_data<T: DeserializeOwned>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    T::deserialize(toml_of(obj, what, true, 0)?)
        .map_err(|e| HilError::serde(what, e.message().trim().to_string()))
        .py_err()
}

/// [`to_toml`] at nesting `depth`; with `skip_none`, dict entries that are
/// None are left out.
fn toml_of(
    obj: &Bound<'_, PyAny>,
    what: &str,
    skip_none: bool,
    depth: usize,
) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
    check_depth(what, depth)?;
    if obj.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            Err(_) => Err(crate::errors::to_py_err(HilError::invalid_input(
                what,
                format!("the int {obj} does not fit in 64 signed bits"),
            ))),
        };
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
            if skip_none && v.is_none() {
                continue;
            }
            let key: String = k.extract()?;
            let value = toml_of(&v, &format!("{what}.{key}"), skip_none, depth + 1)?;
            t.insert(key, value);
        }
        return Ok(toml::Value::Table(t));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj
            .try_iter()?
            .map(|v| toml_of(&v?, what, skip_none, depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    // NumPy scalars and arrays: through their Python form.
    if obj.hasattr("tolist")? {
        return toml_of(&obj.call_method0("tolist")?, what, skip_none, depth + 1);
    }
    Err(crate::errors::to_py_err(HilError::invalid_input(
        what,
        format!(
            "a {} cannot be a config value (use bool, int, float, str, list or dict)",
            obj.get_type().name()?
        ),
    )))
}
