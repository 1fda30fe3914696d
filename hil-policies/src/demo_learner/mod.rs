//! A small seeded learning policy that sometimes asks (`type =
//! "demo_learner"`), for trying the channels and the interaction record
//! without a robot.
//!
//! It is deliberately simple and is not one of the paper's policies (those
//! are the other modules of this crate).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use hil_config::PolicyConfig;
use hil_config::TaskContext;
use hil_core::policy::{check_feedback, check_input};
use hil_core::{
    ArmDiagnostics, ArmId, Context, Decision, DecisionInput, Diagnostics, Feedback, HilError,
    Policy, QueryKind, Result,
};

/// Config of the demo learner, `type = "demo_learner"`:
///
/// ```toml
/// [policy]
/// type = "demo_learner"
/// query_probability = 0.5   # chance of asking at an item's first attempt
/// epsilon = 0.1             # chance of a random action otherwise
/// kinds = [{ response = "mcq" }, { response = "bounding_box", difficulty = "hard" }]
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoLearnerConfig {
    /// Probability in [0, 1] of asking at the first attempt of an item.
    pub query_probability: f64,
    /// Probability in [0, 1] of a uniformly random action when acting.
    #[serde(default)]
    pub epsilon: f64,
    /// Kinds of query, used in turn (default: one easy MCQ).
    #[serde(default)]
    pub kinds: Vec<QueryKind>,
}

#[typetag::serde(name = "demo_learner")]
impl PolicyConfig for DemoLearnerConfig {
    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn Policy>> {
        self.validate()?;
        Ok(Box::new(DemoLearner::new(
            ctx.action_space().len(),
            ctx.context_dim(),
            self.clone(),
        )))
    }

    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("query_probability", self.query_probability),
            ("epsilon", self.epsilon),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(HilError::invalid_parameter(
                    name,
                    v,
                    "must be a probability in [0, 1]",
                ));
            }
        }
        Ok(())
    }
}

/// A small seeded learner: per context feature and arm it keeps a weighted
/// success count, acts greedily on it (with ε-exploration), and asks with a
/// fixed probability at an item's first attempt.
///
/// ```
/// use hil_core::{Choice, Context, DecisionInput, Policy, QueryHistory, WorkloadForecast};
/// use hil_policies::demo_learner::{DemoLearner, DemoLearnerConfig};
///
/// let params = DemoLearnerConfig { query_probability: 1.0, epsilon: 0.0, kinds: vec![] };
/// let mut learner = DemoLearner::new(3, 2, params);
/// let context = Context::new(vec![1.0, 0.0])?;
/// let history = QueryHistory::new();
/// let input = DecisionInput::new(&context, 1, WorkloadForecast::none(&history));
/// // With query_probability = 1 it asks at every first attempt.
/// assert!(matches!(learner.decide(&input)?.choice, Choice::Query { .. }));
/// # Ok::<(), hil_core::HilError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DemoLearner {
    n_arms: usize,
    dim: usize,
    params: DemoLearnerConfig,
    /// Per arm, per feature: (reward-weighted sum, weight sum).
    stats: Vec<Vec<(f64, f64)>>,
    asked: usize,
    rng: ChaCha8Rng,
}

#[derive(Serialize, Deserialize)]
struct LearnerState {
    stats: Vec<Vec<(f64, f64)>>,
    asked: usize,
    rng_seed: [u8; 32],
    rng_stream: u64,
    /// Decimal: JSON numbers cannot hold a u128.
    rng_word_pos: String,
}

impl DemoLearner {
    /// A learner over `n_arms` arms and `dim`-dimensional contexts.
    pub fn new(n_arms: usize, dim: usize, params: DemoLearnerConfig) -> Self {
        Self {
            n_arms,
            dim,
            params,
            stats: vec![vec![(0.0, 0.0); dim]; n_arms],
            asked: 0,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }

    fn estimate(&self, x: &Context, arm: usize) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for (i, v) in x.as_slice().iter().enumerate() {
            let w = v.abs();
            num += w * self.stats[arm][i].0;
            den += w * self.stats[arm][i].1;
        }
        // Optimistic prior: untried arms look good, so they get tried.
        (num + 1.0) / (den + 1.0)
    }
}

impl Policy for DemoLearner {
    fn name(&self) -> &str {
        "demo_learner"
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        check_input(self, input)?;
        let estimates: Vec<f64> = (0..self.n_arms)
            .map(|a| self.estimate(input.context, a))
            .collect();
        let mut greedy = 0;
        for (a, e) in estimates.iter().enumerate() {
            if *e > estimates[greedy] {
                greedy = a;
            }
        }
        let explore = self.rng.random_bool(self.params.epsilon);
        let random_arm = self.rng.random_range(0..self.n_arms);
        let ask = self.rng.random_bool(self.params.query_probability);
        let arm = ArmId(if explore { random_arm } else { greedy });
        let diagnostics = Diagnostics::new()
            .with_arms(
                estimates
                    .iter()
                    .map(|e| ArmDiagnostics::new(*e, 0.0, *e))
                    .collect(),
            )
            .with_query_probability(if input.attempt == 0 {
                self.params.query_probability
            } else {
                0.0
            });
        let decision = if input.attempt == 0 && ask {
            let kind = if self.params.kinds.is_empty() {
                QueryKind::default()
            } else {
                self.params.kinds[self.asked % self.params.kinds.len()]
            };
            self.asked += 1;
            Decision::query(kind, arm)
        } else {
            Decision::act(arm)
        };
        Ok(decision.with_diagnostics(diagnostics))
    }
    fn observe(&mut self, f: &Feedback<'_>) -> Result<()> {
        check_feedback(self, f)?;
        for (i, v) in f.context.as_slice().iter().enumerate() {
            let w = v.abs();
            self.stats[f.arm.0][i].0 += w * f.reward;
            self.stats[f.arm.0][i].1 += w;
        }
        Ok(())
    }
    fn save(&self) -> Result<Value> {
        serde_json::to_value(LearnerState {
            stats: self.stats.clone(),
            asked: self.asked,
            rng_seed: self.rng.get_seed(),
            rng_stream: self.rng.get_stream(),
            rng_word_pos: self.rng.get_word_pos().to_string(),
        })
        .map_err(|e| HilError::serde("demo_learner state", e))
    }
    fn restore(&mut self, state: Value) -> Result<()> {
        let s: LearnerState =
            serde_json::from_value(state).map_err(|e| HilError::serde("demo_learner state", e))?;
        if s.stats.len() != self.n_arms || s.stats.iter().any(|r| r.len() != self.dim) {
            return Err(HilError::state(
                "demo_learner",
                format!(
                    "checkpoint shape does not match {} arms × d = {}",
                    self.n_arms, self.dim
                ),
            ));
        }
        let word_pos: u128 = s
            .rng_word_pos
            .parse()
            .map_err(|e| HilError::serde("demo_learner state field `rng_word_pos`", e))?;
        self.stats = s.stats;
        self.asked = s.asked;
        let mut rng = ChaCha8Rng::from_seed(s.rng_seed);
        rng.set_stream(s.rng_stream);
        rng.set_word_pos(word_pos);
        self.rng = rng;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_conformance::check_policy;

    fn params(query_probability: f64, epsilon: f64) -> DemoLearnerConfig {
        DemoLearnerConfig {
            query_probability,
            epsilon,
            kinds: vec![],
        }
    }

    #[test]
    fn the_demo_learner_conforms() {
        check_policy(&|| Ok(Box::new(DemoLearner::new(6, 5, params(0.4, 0.2))))).unwrap();
    }

    #[test]
    fn configs_are_checked() {
        let ctx = TaskContext::new(
            hil_config::BuildContext::new(".", 0),
            hil_core::ActionSpace::new(["a", "b"]).unwrap(),
            3,
        );
        assert!(params(0.5, 0.1).build(&ctx).is_ok());
        for bad in [params(1.5, 0.1), params(0.5, -0.1)] {
            assert!(matches!(
                bad.build(&ctx),
                Err(HilError::InvalidParameter { .. })
            ));
        }
    }
}
