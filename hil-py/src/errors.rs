//! hil's errors as Python exceptions: one class per [`hil_core::HilError`]
//! kind, each a subclass of `hil.HilError`, carrying the Rust error's
//! structured fields as attributes (`path`, `record`, `field`, `line`,
//! `name`, ...). Tests match the class and the attributes, never the text.
//!
//! A Python exception raised inside a Python component travels through
//! hil's Rust code as a [`HilError::Backend`] whose source is the original
//! [`PyErr`]; converting it back sets that exception as `__cause__`, so the
//! Python traceback survives the round trip.

use hil_core::HilError as RustError;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyDict;

create_exception!(
    hil,
    HilError,
    PyException,
    "Base class of every error raised by hil. `kind` names the Rust error variant."
);
create_exception!(
    hil,
    InvalidInputError,
    HilError,
    "A value handed to a component is outside what it accepts (`what`, `why`)."
);
create_exception!(
    hil,
    DimensionMismatchError,
    HilError,
    "A context has the wrong dimension (`expected`, `got`)."
);
create_exception!(
    hil,
    ArmOutOfRangeError,
    HilError,
    "An arm index is not in the action space (`arm`, `n_arms`)."
);
create_exception!(
    hil,
    InvalidParameterError,
    HilError,
    "A hyperparameter or setting failed validation (`name`, `value`, `why`)."
);
create_exception!(
    hil,
    ConfigError,
    HilError,
    "A configuration file could not be parsed or validated (`path`, `line`, `column`, `field`, `why`)."
);
create_exception!(
    hil,
    IoError,
    HilError,
    "Reading or writing a file failed (`op`, `path`)."
);
create_exception!(
    hil,
    DataError,
    HilError,
    "A data file is malformed (`path`, `record`, `field`, `why`)."
);
create_exception!(
    hil,
    SerdeError,
    HilError,
    "(De)serialising state or parameters failed (`what`)."
);
create_exception!(
    hil,
    NumericalError,
    HilError,
    "A numerical routine failed (`what`)."
);
create_exception!(
    hil,
    StateError,
    HilError,
    "A component refused a call in its current state (`component`, `why`)."
);
create_exception!(
    hil,
    ChannelError,
    HilError,
    "A query channel failed (`channel`, `why`)."
);
create_exception!(
    hil,
    BackendError,
    HilError,
    "A backend failed (`backend`, `why`); a Python component's exception is its `__cause__`."
);
create_exception!(
    hil,
    UnsupportedError,
    HilError,
    "A component does not support what it was asked (`component`, `operation`, `why`), e.g. the Kinova environment in a build without MuJoCo."
);
create_exception!(
    hil,
    PluginError,
    HilError,
    "A plugin failed to load, handshake or run (`path`, `why`)."
);
create_exception!(
    hil,
    ConformanceError,
    HilError,
    "A conformance check failed (`subject`, `check`, `detail`, `hint`)."
);

/// The exception class and structured fields of a hil error.
fn class_and_fields<'py>(
    py: Python<'py>,
    error: &RustError,
) -> PyResult<(
    Bound<'py, pyo3::types::PyType>,
    &'static str,
    Bound<'py, PyDict>,
)> {
    let d = PyDict::new(py);
    let (ty, kind) = match error {
        RustError::InvalidInput { what, why } => {
            d.set_item("what", what)?;
            d.set_item("why", why)?;
            (py.get_type::<InvalidInputError>(), "InvalidInput")
        }
        RustError::DimensionMismatch { expected, got } => {
            d.set_item("expected", expected)?;
            d.set_item("got", got)?;
            (py.get_type::<DimensionMismatchError>(), "DimensionMismatch")
        }
        RustError::ArmOutOfRange { arm, n_arms } => {
            d.set_item("arm", arm)?;
            d.set_item("n_arms", n_arms)?;
            (py.get_type::<ArmOutOfRangeError>(), "ArmOutOfRange")
        }
        RustError::InvalidParameter { name, value, why } => {
            d.set_item("name", name)?;
            d.set_item("value", value)?;
            d.set_item("why", why)?;
            (py.get_type::<InvalidParameterError>(), "InvalidParameter")
        }
        RustError::Config(c) => {
            d.set_item("path", c.path.to_string_lossy())?;
            d.set_item("line", c.line)?;
            d.set_item("column", c.column)?;
            d.set_item("field", c.field.clone())?;
            d.set_item("why", &c.message)?;
            (py.get_type::<ConfigError>(), "Config")
        }
        RustError::Io { op, path, .. } => {
            d.set_item("op", *op)?;
            d.set_item("path", path.to_string_lossy())?;
            (py.get_type::<IoError>(), "Io")
        }
        RustError::Data {
            path,
            record,
            field,
            why,
        } => {
            d.set_item("path", path.to_string_lossy())?;
            d.set_item("record", record)?;
            d.set_item("field", field)?;
            d.set_item("why", why)?;
            (py.get_type::<DataError>(), "Data")
        }
        RustError::Serde { what, .. } => {
            d.set_item("what", what)?;
            (py.get_type::<SerdeError>(), "Serde")
        }
        RustError::Numerical { what, .. } => {
            d.set_item("what", what)?;
            (py.get_type::<NumericalError>(), "Numerical")
        }
        RustError::State { component, why } => {
            d.set_item("component", component)?;
            d.set_item("why", why)?;
            (py.get_type::<StateError>(), "State")
        }
        RustError::Channel { channel, why, .. } => {
            d.set_item("channel", channel)?;
            d.set_item("why", why)?;
            (py.get_type::<ChannelError>(), "Channel")
        }
        RustError::Backend { backend, why, .. } => {
            d.set_item("backend", backend)?;
            d.set_item("why", why)?;
            (py.get_type::<BackendError>(), "Backend")
        }
        RustError::Unsupported {
            component,
            operation,
            why,
        } => {
            d.set_item("component", component)?;
            d.set_item("operation", operation)?;
            d.set_item("why", why)?;
            (py.get_type::<UnsupportedError>(), "Unsupported")
        }
        RustError::Plugin { path, why } => {
            d.set_item("path", path.to_string_lossy())?;
            d.set_item("why", why)?;
            (py.get_type::<PluginError>(), "Plugin")
        }
        // A kind added to hil-core later: the base class, still with `kind`.
        _ => (py.get_type::<HilError>(), "Other"),
    };
    Ok((ty, kind, d))
}

/// Converts a hil error into the Python exception that represents it.
pub(crate) fn to_py_err(error: RustError) -> PyErr {
    Python::attach(|py| {
        let message = error.to_string();
        let built = (|| -> PyResult<PyErr> {
            let (ty, kind, fields) = class_and_fields(py, &error)?;
            let value = ty.call1((message.clone(),))?;
            value.setattr("kind", kind)?;
            for (k, v) in fields.iter() {
                value.setattr(k.cast::<pyo3::types::PyString>()?, v)?;
            }
            let err = PyErr::from_value(value);
            // A Python component's own exception, kept as the source.
            if let Some(cause) = python_cause(&error) {
                err.set_cause(py, Some(cause.clone_ref(py)));
            }
            Ok(err)
        })();
        built.unwrap_or_else(|_| HilError::new_err(message))
    })
}

/// The [`PyErr`] somewhere in `error`'s source chain, if any.
fn python_cause(error: &RustError) -> Option<&PyErr> {
    let mut source = std::error::Error::source(error);
    while let Some(s) = source {
        if let Some(e) = s.downcast_ref::<PyErr>() {
            return Some(e);
        }
        source = s.source();
    }
    None
}

/// `Result<T, HilError>` into `PyResult<T>`.
pub(crate) trait IntoPy<T> {
    /// The same result with the error as its Python exception.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for hil_core::Result<T> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py_err)
    }
}

/// A Python exception raised by `component` (e.g. ``python policy `mine` ``)
/// during `call`, as the hil error hil's Rust code propagates: a hil
/// exception raised on purpose (e.g. `DimensionMismatchError` with its
/// attributes) becomes its own kind again; anything else becomes a
/// [`RustError::Backend`] naming the component and the call, with the
/// Python exception (and so its traceback) kept as the source.
pub(crate) fn from_py_err(py: Python<'_>, component: &str, call: &str, err: PyErr) -> RustError {
    if let Some(e) = rebuild_hil_error(py, &err) {
        return e;
    }
    let why = match raised_at(py, &err) {
        Some(at) => format!("{call} raised {err} (at {at})"),
        None => format!("{call} raised {err}"),
    };
    RustError::backend(component, why).with_source(err)
}

/// `file:line in function` of the innermost frame of `err`'s traceback,
/// so that a message read on the Rust side (a log, a protocol error) says
/// where the Python code failed.
fn raised_at(py: Python<'_>, err: &PyErr) -> Option<String> {
    let mut tb = err.traceback(py)?.into_any();
    while let Ok(next) = tb.getattr("tb_next") {
        if next.is_none() {
            break;
        }
        tb = next;
    }
    let line: usize = tb.getattr("tb_lineno").ok()?.extract().ok()?;
    let code = tb.getattr("tb_frame").ok()?.getattr("f_code").ok()?;
    let file: String = code.getattr("co_filename").ok()?.extract().ok()?;
    let function: String = code.getattr("co_name").ok()?.extract().ok()?;
    Some(format!("{file}:{line} in {function}"))
}

/// The Rust error of a hil exception that carries its attributes.
fn rebuild_hil_error(py: Python<'_>, err: &PyErr) -> Option<RustError> {
    let v = err.value(py);
    let get = |name: &str| v.getattr(name).ok();
    let usize_of = |name: &str| get(name)?.extract::<usize>().ok();
    let string_of = |name: &str| get(name)?.extract::<String>().ok();
    if err.is_instance_of::<DimensionMismatchError>(py) {
        return Some(RustError::DimensionMismatch {
            expected: usize_of("expected")?,
            got: usize_of("got")?,
        });
    }
    if err.is_instance_of::<ArmOutOfRangeError>(py) {
        return Some(RustError::ArmOutOfRange {
            arm: usize_of("arm")?,
            n_arms: usize_of("n_arms")?,
        });
    }
    if err.is_instance_of::<InvalidParameterError>(py) {
        return Some(RustError::InvalidParameter {
            name: string_of("name")?,
            value: string_of("value").unwrap_or_default(),
            why: string_of("why").unwrap_or_default(),
        });
    }
    if err.is_instance_of::<StateError>(py) {
        return Some(RustError::state(string_of("component")?, string_of("why")?));
    }
    if err.is_instance_of::<InvalidInputError>(py) {
        return Some(RustError::invalid_input(
            string_of("what")?,
            string_of("why")?,
        ));
    }
    None
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("HilError", py.get_type::<HilError>())?;
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add(
        "DimensionMismatchError",
        py.get_type::<DimensionMismatchError>(),
    )?;
    m.add("ArmOutOfRangeError", py.get_type::<ArmOutOfRangeError>())?;
    m.add(
        "InvalidParameterError",
        py.get_type::<InvalidParameterError>(),
    )?;
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("IoError", py.get_type::<IoError>())?;
    m.add("DataError", py.get_type::<DataError>())?;
    m.add("SerdeError", py.get_type::<SerdeError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("StateError", py.get_type::<StateError>())?;
    m.add("ChannelError", py.get_type::<ChannelError>())?;
    m.add("BackendError", py.get_type::<BackendError>())?;
    m.add("PluginError", py.get_type::<PluginError>())?;
    m.add("UnsupportedError", py.get_type::<UnsupportedError>())?;
    m.add("ConformanceError", py.get_type::<ConformanceError>())?;
    Ok(())
}
