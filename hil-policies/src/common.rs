//! The pieces every estimator-based policy shares: scoring with
//! diagnostics, arg-max, learning from feedback, and checkpoint framing.

use hil_core::{
    ArmDiagnostics, ArmId, BuildContext, DecisionInput, Diagnostics, Feedback, HilError, Policy,
    Result,
};
use serde_json::{Value, json};

use crate::estimator::{ArmEstimate, EstimatorOptions, LinearArms};

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

/// Scores every arm at the decision's context and fills the per-arm diagnostics.
/// The estimator validates the context (dimension, finiteness).
pub(crate) fn score(
    arms: &mut LinearArms,
    input: &DecisionInput<'_>,
    alpha: f64,
) -> Result<(Vec<ArmEstimate>, Diagnostics)> {
    let s = arms.scores(input.context)?;
    let diag = Diagnostics {
        arms: s
            .iter()
            .map(|e| ArmDiagnostics {
                estimate: e.estimate,
                bonus: e.bonus,
                ucb: e.ucb(alpha),
            })
            .collect(),
        ..Default::default()
    };
    Ok((s, diag))
}

/// The arm LinUCB would play: argmax θᵀx + α·b(x).
pub(crate) fn ucb_arm(scores: &[ArmEstimate], alpha: f64) -> ArmId {
    ArmId(argmax(scores, |s| s.ucb(alpha)))
}

/// Updates the estimator with the executed arm and its reward (the
/// expert's arm after a query, too). The estimator validates the context,
/// the arm and the reward.
pub(crate) fn learn(arms: &mut LinearArms, fb: &Feedback<'_>) -> Result<()> {
    arms.update(fb.context, fb.arm, fb.reward)
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

/// The default ridge strength λ in configs.
pub(crate) fn default_lambda() -> f64 {
    1.0
}

/// Builds the estimator a policy config asks for, pretrained on the
/// environment's offline data if `pretrain` is set.
pub(crate) fn build_estimator(
    ctx: &BuildContext,
    lambda: f64,
    pretrain: bool,
    options: EstimatorOptions,
) -> Result<LinearArms> {
    let n_arms = ctx.action_space.as_ref().map(|a| a.len()).ok_or_else(|| {
        HilError::state(
            "policy config",
            "the action space is unknown (build the environment first)",
        )
    })?;
    let dim = ctx.context_dim.ok_or_else(|| {
        HilError::state(
            "policy config",
            "the context dimension is unknown (build the environment first)",
        )
    })?;
    let mut arms = LinearArms::with_options(n_arms, dim, lambda, options)?;
    if pretrain {
        let data = ctx.pretraining.as_ref().ok_or_else(|| {
            HilError::invalid_parameter(
                "pretrain",
                true,
                "pretraining was requested but the environment offers no pretraining data",
            )
        })?;
        arms.pretrain(data)?;
    }
    Ok(arms)
}
