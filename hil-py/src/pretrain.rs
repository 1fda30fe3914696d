//! Pretraining a Python policy as hil pretrains its own: a config with
//! `pretrain = true` (what the paper's protocol gives every method) hands
//! the environment's offline data (`TaskContext::pretraining`, e.g. the
//! protocol's pretraining foods) to the policy's
//! `pretrain(contexts, arms, rewards)` method right after its factory built
//! it, so a Python method is compared on the same footing as the built-in
//! ones (hil-py/README.md, "Pretraining").

use std::sync::{Arc, Mutex};

use hil_config::TaskContext;
use hil_core::{HilError, LabelledObservation, Result};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyTuple};
use serde_json::Value;

use crate::errors::{IntoPy, to_py_err};

/// The key of a Python policy's table that asks for pretraining; hil
/// consumes it, the factory never sees it.
pub(crate) const KEY: &str = "pretrain";

/// `params` without [`KEY`], and whether it asked for pretraining (false
/// when absent, as for hil's own policies).
pub(crate) fn take_flag(mut params: Value) -> Result<(Value, bool)> {
    let flag = match params.as_object_mut().and_then(|o| o.remove(KEY)) {
        None => false,
        Some(Value::Bool(b)) => b,
        Some(other) => {
            return Err(HilError::invalid_parameter(
                KEY,
                other,
                "must be true or false",
            ));
        }
    };
    Ok((params, flag))
}

/// Calls `policy.pretrain(contexts, arms, rewards)` with the pretraining
/// data `ctx` offers: an (n, d) float64 array, an (n,) int64 array and an
/// (n,) float64 array, read-only (one copy serves every policy built from
/// the same data). Refused, naming `pretrain`, when there is no data or no
/// such method.
pub(crate) fn pretrain(policy: &Bound<'_, PyAny>, ctx: &TaskContext) -> PyResult<()> {
    let refuse = |why: String| Err(to_py_err(HilError::invalid_parameter(KEY, true, why)));
    let data = ctx.required_pretraining().py_err()?;
    if !policy.hasattr("pretrain")? {
        return refuse(format!(
            "the Python policy {} has no pretrain(contexts, arms, rewards) method: add one, \
             or set pretrain = false to run it unpretrained",
            policy.get_type().name()?
        ));
    }
    let arrays = arrays(policy.py(), data)?;
    policy.call_method1("pretrain", arrays.bind(policy.py()))?;
    Ok(())
}

/// The last data converted and its arrays: a protocol builds hundreds of
/// policies from one context, and the data (e.g. 2,160 × 2,048 floats) need
/// cross only once. The `Arc` is kept so its address cannot be reused.
type Converted = (Arc<[LabelledObservation]>, Py<PyTuple>);
static LAST: Mutex<Option<Converted>> = Mutex::new(None);

/// `(contexts, arms, rewards)` of `data` as read-only NumPy arrays.
fn arrays(py: Python<'_>, data: &Arc<[LabelledObservation]>) -> PyResult<Py<PyTuple>> {
    // The lock is never held across a Python call (which may let another
    // thread take the GIL and wait for the lock).
    let last = || LAST.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((held, arrays)) = last().as_ref()
        && Arc::ptr_eq(held, data)
    {
        return Ok(arrays.clone_ref(py));
    }
    let d = data.first().map_or(0, |o| o.context.len());
    let mut x = Vec::with_capacity(data.len() * d);
    for o in data.iter() {
        x.extend_from_slice(o.context.as_slice());
    }
    let contexts = PyArray1::from_vec(py, x).reshape([data.len(), d])?;
    let arms = PyArray1::from_iter(py, data.iter().map(|o| o.arm.0 as i64));
    let rewards = PyArray1::from_iter(py, data.iter().map(|o| o.reward));
    let tuple = PyTuple::new(
        py,
        [contexts.into_any(), arms.into_any(), rewards.into_any()],
    )?;
    for a in tuple.iter() {
        a.getattr("setflags")?
            .call((), Some(&[("write", false)].into_py_dict(py)?))?;
    }
    let tuple = tuple.unbind();
    *last() = Some((data.clone(), tuple.clone_ref(py)));
    Ok(tuple)
}
