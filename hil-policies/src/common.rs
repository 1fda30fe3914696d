//! Arg-max and checkpoint framing, shared by [`crate::LinearPolicy`] and
//! the query gap.

use hil_core::{HilError, Policy, Result};
use serde_json::{Value, json};

use crate::estimator::{ArmEstimate, LinearArms};

/// The arm with the largest `key` (the lowest index among ties).
pub(crate) fn argmax(scores: &[ArmEstimate], key: impl Fn(&ArmEstimate) -> f64) -> usize {
    let mut best = 0;
    for (i, s) in scores.iter().enumerate().skip(1) {
        if key(s) > key(&scores[best]) {
            best = i;
        }
    }
    best
}

/// A checkpoint: the policy name, the estimator, and policy-specific extras.
pub(crate) fn save(name: &str, arms: &LinearArms, extra: Value) -> Value {
    json!({ "policy": name, "arms": arms.save_state(), "extra": extra })
}

/// Restores a checkpoint made by [`save`] for a policy of the same kind and
/// shape; returns the estimator and the extras.
pub(crate) fn restore(policy: &dyn Policy, state: Value) -> Result<(LinearArms, Value)> {
    let Value::Object(mut m) = state else {
        return Err(HilError::serde(
            format!("{} state", policy.name()),
            "expected a JSON object",
        ));
    };
    let name = m.get("policy").and_then(Value::as_str).unwrap_or("");
    if name != policy.name() {
        return Err(HilError::state(
            policy.name(),
            format!("cannot restore a checkpoint of policy `{name}`"),
        ));
    }
    let arms = LinearArms::from_state(m.remove("arms").unwrap_or(Value::Null))?;
    if arms.n_arms() != policy.n_arms() || arms.dim() != policy.dim() {
        return Err(HilError::state(
            policy.name(),
            format!(
                "checkpoint has {} arms × d = {}, this policy {} arms × d = {}",
                arms.n_arms(),
                arms.dim(),
                policy.n_arms(),
                policy.dim()
            ),
        ));
    }
    Ok((arms, m.remove("extra").unwrap_or(Value::Null)))
}
