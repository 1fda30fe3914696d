//! A hil plugin: the `ask_first_items` policy.
//!
//! It asks the person at the first attempt of each of the first `n_ask`
//! items, and otherwise acts with the arm whose observed success rate is
//! highest (ties go to the lowest arm). Contexts are only checked, not used:
//! this is the smallest policy worth loading, not a good one.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use hil_config::TaskContext;
use hil_core::policy::{check_feedback, check_input};
use hil_core::{ArmId, Decision, DecisionInput, Feedback, HilError, Policy, QueryKind, Result};
use hil_plugin::{Params, Registrar};

/// The parameters, as written in a config's `[policy]` section.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AskFirstParams {
    /// How many items to ask about.
    n_ask: usize,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct AskFirstItems {
    n_ask: usize,
    dim: usize,
    /// Per arm: (successes, attempts).
    counts: Vec<(f64, f64)>,
}

impl Policy for AskFirstItems {
    fn name(&self) -> &str {
        "ask_first_items"
    }
    fn n_arms(&self) -> usize {
        self.counts.len()
    }
    fn dim(&self) -> usize {
        self.dim
    }

    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        check_input(self, input)?;
        let rate = |(s, n): (f64, f64)| if n > 0.0 { s / n } else { 0.0 };
        let mut best = 0;
        for (arm, c) in self.counts.iter().enumerate() {
            if rate(*c) > rate(self.counts[best]) {
                best = arm;
            }
        }
        if input.item_index < self.n_ask && input.attempt == 0 {
            Ok(Decision::query(QueryKind::default(), ArmId(best)))
        } else {
            Ok(Decision::act(ArmId(best)))
        }
    }

    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        check_feedback(self, feedback)?;
        let c = &mut self.counts[feedback.arm.0];
        c.0 += feedback.reward;
        c.1 += 1.0;
        Ok(())
    }

    fn save(&self) -> Result<Value> {
        serde_json::to_value(self).map_err(|e| HilError::serde("ask_first_items state", e))
    }

    fn restore(&mut self, state: Value) -> Result<()> {
        let s: Self = serde_json::from_value(state)
            .map_err(|e| HilError::serde("ask_first_items state", e))?;
        if s.counts.len() != self.counts.len() || s.dim != self.dim {
            return Err(HilError::state(
                "ask_first_items",
                "the checkpoint is for another shape",
            ));
        }
        *self = s;
        Ok(())
    }
}

/// Builds the policy from its parameters and the experiment's shape.
pub fn build(params: &Params, ctx: &TaskContext) -> Result<Box<dyn Policy>> {
    let p: AskFirstParams = params.parse("ask_first_items")?;
    // The context always knows the environment's shape: no check needed.
    let (n_arms, dim) = (ctx.action_space().len(), ctx.context_dim());
    Ok(Box::new(AskFirstItems {
        n_ask: p.n_ask,
        dim,
        counts: vec![(0.0, 0.0); n_arms],
    }))
}

/// Registers every type this library provides.
pub fn register(r: &mut Registrar<'_>) {
    r.policy(
        "ask_first_items",
        "asks about the first items, then repeats the best arm so far",
        build,
    );
}

hil_plugin::declare_plugin!(register);

#[cfg(test)]
mod tests {
    use super::*;
    use hil_conformance::CheckOptions;

    // One test per conformance property, named after it.
    hil_conformance::conformance_tests! {
        policy ask_first_items {
            options: CheckOptions::default().with_context_dim(4),
            make: |opts| build(&Params::toml("n_ask = 2"), &opts.task_context()),
        }
    }
}
