//! A plugin with the mistake the conformance suites exist to catch: the
//! `unchecked_linear` policy scores arms by indexing its weights with the
//! context it is given, without checking the context's length. A longer
//! context panics (the plugin guard turns that into an error and poisons
//! the object); a shorter one is silently accepted. Everything else about
//! it conforms, so `hil plugins check` and its generated tests must fail on
//! exactly one property: `rejects wrong dimension`.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use hil_config::TaskContext;
use hil_core::{ArmId, Decision, DecisionInput, Feedback, HilError, Policy, QueryKind, Result};
use hil_plugin::{Params, Registrar};

#[derive(Debug, Clone, Serialize, Deserialize)]
struct UncheckedLinear {
    /// Per arm, one weight per context feature.
    weights: Vec<Vec<f64>>,
}

impl Policy for UncheckedLinear {
    fn name(&self) -> &str {
        "unchecked_linear"
    }
    fn n_arms(&self) -> usize {
        self.weights.len()
    }
    fn dim(&self) -> usize {
        self.weights[0].len()
    }

    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        // The defect: no `check_input(self, input)?` here.
        let score = |w: &[f64]| -> f64 {
            input
                .context
                .iter()
                .enumerate()
                .map(|(i, x)| w[i] * x)
                .sum()
        };
        let best = (0..self.n_arms())
            .max_by(|&a, &b| score(&self.weights[a]).total_cmp(&score(&self.weights[b])))
            .unwrap_or(0);
        if input.item_index == 0 && input.attempt == 0 {
            Ok(Decision::query(QueryKind::default(), ArmId(best)))
        } else {
            Ok(Decision::act(ArmId(best)))
        }
    }

    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        hil_core::policy::check_feedback(self, feedback)?;
        let w = &mut self.weights[feedback.arm.0];
        for (wi, x) in w.iter_mut().zip(feedback.context.iter()) {
            *wi += 0.1 * (feedback.reward - 0.5) * x;
        }
        Ok(())
    }

    fn save(&self) -> Result<Value> {
        serde_json::to_value(self).map_err(|e| HilError::serde("unchecked_linear state", e))
    }

    fn restore(&mut self, state: Value) -> Result<()> {
        *self = serde_json::from_value(state)
            .map_err(|e| HilError::serde("unchecked_linear state", e))?;
        Ok(())
    }
}

/// Builds the policy for the build context's action space and dimension.
pub fn build(params: &Params, ctx: &TaskContext) -> Result<Box<dyn Policy>> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct P {}
    let _: P = params.parse("unchecked_linear")?;
    Ok(Box::new(UncheckedLinear {
        weights: vec![vec![0.0; ctx.context_dim()]; ctx.action_space().len()],
    }))
}

fn register(r: &mut Registrar<'_>) {
    r.policy(
        "unchecked_linear",
        "a linear scorer that does not check the context's length",
        build,
    );
}

hil_plugin::declare_plugin!(register);

/// One test per property; `rejects_wrong_dimension` fails by design, so
/// they are compiled only with the `generated-tests` feature.
#[cfg(all(test, feature = "generated-tests"))]
mod tests {
    use super::*;
    use hil_conformance::CheckOptions;

    hil_conformance::conformance_tests! {
        policy unchecked_linear {
            options: CheckOptions::default(),
            make: |opts| build(&Params::empty(), &opts.task_context()),
        }
    }
}
