//! Small, real implementations of the four traits for tests of code that
//! consumes them. They are exact and transparent, so hand-worked expectations
//! can be written against them.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

use hil_core::{
    ActionSpace, ArmId, CallOrder, Choice, Context, Decision, DecisionInput, Environment, Feedback,
    HilError, Item, Outcome, Policy, Result, Timestep, WorkloadInput, WorkloadModel,
};

/// An environment whose items have fixed per-arm success probabilities.
///
/// Contexts are the one-hot code of the item's type followed by two noise
/// features drawn from the seeded RNG, so every observation is fresh.
/// Outcomes are Bernoulli draws, or, with [`TableEnv::with_outcomes`], a
/// recorded sequence replayed in order (probabilities are still reported).
#[derive(Debug, Clone)]
pub struct TableEnv {
    actions: ActionSpace,
    items: Vec<(String, Vec<f64>)>,
    types: Vec<String>,
    script: Option<Vec<bool>>,
    rng: ChaCha8Rng,
    next: usize,
    played: usize,
    current: Option<Item>,
    order: CallOrder,
}

impl TableEnv {
    /// An episode of `items`, each a label and one success probability per
    /// action of `actions`.
    pub fn new(actions: ActionSpace, items: Vec<(&str, Vec<f64>)>) -> Result<Self> {
        for (label, p) in &items {
            if p.len() != actions.len() || p.iter().any(|v| !(0.0..=1.0).contains(v)) {
                return Err(HilError::invalid_input(
                    format!("item `{label}`"),
                    format!("needs {} probabilities in [0, 1], got {p:?}", actions.len()),
                ));
            }
        }
        let mut types: Vec<String> = Vec::new();
        for (l, _) in &items {
            if !types.iter().any(|t| t == l) {
                types.push(l.to_string());
            }
        }
        Ok(Self {
            actions,
            items: items.into_iter().map(|(l, p)| (l.to_string(), p)).collect(),
            types,
            script: None,
            rng: ChaCha8Rng::seed_from_u64(0),
            next: 0,
            played: 0,
            current: None,
            order: CallOrder::new("table_env"),
        })
    }

    /// Replays `outcomes` in order instead of sampling.
    pub fn with_outcomes(mut self, outcomes: Vec<bool>) -> Self {
        self.script = Some(outcomes);
        self
    }

    fn item_index(&self) -> Result<usize> {
        self.current
            .as_ref()
            .map(|item| item.index)
            .ok_or_else(|| HilError::state("table_env", "no current item: call next_item first"))
    }

    fn probs(&self) -> Result<&[f64]> {
        Ok(&self.items[self.item_index()?].1)
    }
}

impl Environment for TableEnv {
    fn name(&self) -> &str {
        "table_env"
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        self.types.len() + 2
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.played = 0;
        self.current = None;
        self.order.on_reset();
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        if self.next >= self.items.len() {
            self.current = None;
            self.order.on_next_item(false);
            return Ok(None);
        }
        let item = Item::new(self.next, self.items[self.next].0.clone());
        self.next += 1;
        self.current = Some(item.clone());
        self.order.on_next_item(true);
        Ok(Some(item))
    }
    fn observe(&mut self) -> Result<Context> {
        self.order.on_observe()?;
        let label = &self.items[self.item_index()?].0;
        let mut x: Vec<f64> = self.types.iter().map(|t| f64::from(t == label)).collect();
        x.push(self.rng.random_range(-0.1..0.1));
        x.push(self.rng.random_range(-0.1..0.1));
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.actions.check(arm)?;
        self.order.on_execute()?;
        let p = self.probs()?[arm.0];
        let success = match &self.script {
            Some(s) => *s.get(self.played).ok_or_else(|| {
                HilError::state(
                    "table_env",
                    format!("outcome script ran out after {} attempts", self.played),
                )
            })?,
            None => self.rng.random_bool(p),
        };
        self.played += 1;
        Ok(Outcome::new(success).with_success_probability(p))
    }
    fn best_action(&self) -> Option<ArmId> {
        let p = self.probs().ok()?;
        let mut best = 0;
        for (i, v) in p.iter().enumerate() {
            if *v > p[best] {
                best = i;
            }
        }
        Some(ArmId(best))
    }
    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref()
    }
}

/// A policy that plays a fixed script of choices, then repeats the last one.
/// It records every piece of feedback it receives.
#[derive(Debug, Clone)]
pub struct ScriptedPolicy {
    n_arms: usize,
    dim: usize,
    script: Vec<Choice>,
    next: usize,
    /// Every `(t, arm, reward, from_expert)` observed, in order.
    pub feedback: Vec<(Timestep, ArmId, f64, bool)>,
}

impl ScriptedPolicy {
    /// A policy over `n_arms` arms and `dim`-dimensional contexts.
    pub fn new(n_arms: usize, dim: usize, script: Vec<Choice>) -> Self {
        Self {
            n_arms,
            dim,
            script,
            next: 0,
            feedback: Vec::new(),
        }
    }
}

impl Policy for ScriptedPolicy {
    fn name(&self) -> &str {
        "scripted"
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        hil_core::policy::check_input(self, input)?;
        let choice = self
            .script
            .get(self.next)
            .or(self.script.last())
            .copied()
            .unwrap_or(Choice::Act { arm: ArmId(0) });
        self.next += 1;
        Ok(Decision {
            choice,
            diagnostics: Default::default(),
        })
    }
    fn observe(&mut self, f: &Feedback<'_>) -> Result<()> {
        hil_core::policy::check_feedback(self, f)?;
        self.feedback.push((f.t, f.arm, f.reward, f.from_expert));
        Ok(())
    }
    fn save(&self) -> Result<Value> {
        Ok(json!({ "next": self.next, "feedback": self.feedback }))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        struct S {
            next: usize,
            feedback: Vec<(Timestep, ArmId, f64, bool)>,
        }
        let s: S = serde_json::from_value(state)
            .map_err(|e| HilError::serde("scripted policy state", e))?;
        self.next = s.next;
        self.feedback = s.feedback;
        Ok(())
    }
}

/// WL_t = clamp(WL_0 + increment · (number of queries up to t), 0, 1).
#[derive(Debug, Clone, Copy)]
pub struct CountingWorkload {
    increment: f64,
}

impl CountingWorkload {
    /// Each query adds `increment`.
    pub fn new(increment: f64) -> Self {
        Self { increment }
    }
}

impl WorkloadModel for CountingWorkload {
    fn name(&self) -> &str {
        "counting"
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        let n = input.history.count_until(input.t);
        Ok((input.wl0 + self.increment * n as f64).clamp(0.0, 1.0))
    }
}
