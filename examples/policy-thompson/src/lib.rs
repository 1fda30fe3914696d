//! Example plugin: **linear Thompson sampling** with its own querying rule.
//!
//! Each arm keeps a Bayesian linear model of the reward, r ≈ θ_aᵀx, with
//! posterior N(A_a⁻¹b_a, v²A_a⁻¹) (A_a = λI + Σxxᵀ, b_a = Σ r x). To decide,
//! the policy draws `samples` posterior scores per arm; the first draw picks
//! the arm (Thompson sampling), and the share of draws in which that arm
//! also wins is its *agreement*. When the agreement is below `confidence`
//! the policy is unsure and asks the person, unless the workload model
//! forecasts that asking now would push workload above `max_workload`.
//!
//! Only the score θᵀx is needed, and it is Gaussian with mean μᵀx and
//! standard deviation v·sqrt(xᵀA⁻¹x), so each draw is one scalar normal and
//! A⁻¹ is kept up to date by Sherman–Morrison (O(d²) per step).
//!
//! Built as a `cdylib` it is a hil plugin registering the policy type
//! `linear_thompson`; as an `rlib` the same type can be linked statically.
//!
//! ```
//! use hil_core::{ActionSpace, Policy};
//! use hil_config::{BuildContext, TaskContext};
//! use hil_plugin::Params;
//! let actions = ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap();
//! let ctx = TaskContext::new(BuildContext::new(".", 7), actions, 4);
//! let p = hil_example_policy_thompson::build(&Params::toml("confidence = 0.7"), &ctx).unwrap();
//! assert_eq!((p.n_arms(), p.dim()), (6, 4));
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use hil_config::TaskContext;
use hil_core::policy::{check_feedback, check_input};
use hil_core::{
    ArmDiagnostics, ArmId, Decision, DecisionInput, Diagnostics, Feedback, HilError, Policy,
    QueryKind, Result,
};
use hil_plugin::{Params, Registrar};

/// The name the plugin registers.
pub const NAME: &str = "linear_thompson";

/// Parameters (all optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThompsonParams {
    /// Posterior scale v (> 0).
    pub v: f64,
    /// Ridge prior λ (> 0).
    pub lambda: f64,
    /// Posterior draws per arm per decision (≥ 2).
    pub samples: usize,
    /// Ask when the chosen arm wins fewer than this share of draws (0..=1).
    pub confidence: f64,
    /// Never ask if the forecast workload after asking exceeds this (0..=1).
    pub max_workload: f64,
    /// The kind of query to ask.
    pub query: QueryKind,
}

impl Default for ThompsonParams {
    fn default() -> Self {
        Self {
            v: 0.3,
            lambda: 1.0,
            samples: 16,
            confidence: 0.5,
            max_workload: 0.8,
            query: QueryKind::default(),
        }
    }
}

impl ThompsonParams {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(HilError::invalid_parameter(
                    name,
                    v,
                    "must be finite and > 0",
                ))
            }
        };
        let unit = |name: &str, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(HilError::invalid_parameter(name, v, "must be in [0, 1]"))
            }
        };
        positive("v", self.v)?;
        positive("lambda", self.lambda)?;
        unit("confidence", self.confidence)?;
        unit("max_workload", self.max_workload)?;
        if self.samples < 2 {
            return Err(HilError::invalid_parameter(
                "samples",
                self.samples,
                "must be at least 2",
            ));
        }
        Ok(())
    }
}

/// One arm's posterior.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Arm {
    /// A⁻¹, row-major d×d.
    a_inv: Vec<f64>,
    /// b = Σ r x.
    b: Vec<f64>,
}

impl Arm {
    fn new(dim: usize, lambda: f64) -> Self {
        let mut a_inv = vec![0.0; dim * dim];
        for i in 0..dim {
            a_inv[i * dim + i] = 1.0 / lambda;
        }
        Self {
            a_inv,
            b: vec![0.0; dim],
        }
    }

    /// A⁻¹x.
    fn solve(&self, x: &[f64]) -> Vec<f64> {
        let d = x.len();
        (0..d)
            .map(|i| (0..d).map(|j| self.a_inv[i * d + j] * x[j]).sum())
            .collect()
    }

    /// (mean score μᵀx, width sqrt(xᵀA⁻¹x)).
    fn score(&self, x: &[f64]) -> (f64, f64) {
        let ax = self.solve(x);
        // μᵀx = bᵀA⁻¹x since A⁻¹ is symmetric.
        let mean = dot(&self.b, &ax);
        let width = dot(x, &ax).max(0.0).sqrt();
        (mean, width)
    }

    /// Sherman–Morrison update of A⁻¹ with x, and b += r x.
    fn update(&mut self, x: &[f64], r: f64) {
        let d = x.len();
        let ax = self.solve(x);
        let denom = 1.0 + dot(x, &ax);
        for i in 0..d {
            for j in 0..d {
                self.a_inv[i * d + j] -= ax[i] * ax[j] / denom;
            }
            self.b[i] += r * x[i];
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A standard normal draw (Box–Muller; one of the pair is discarded so the
/// stream of draws is simple to replay).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>(); // in (0, 1]
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Linear Thompson sampling with a disagreement-based querying rule.
#[derive(Clone, Debug)]
pub struct LinearThompson {
    params: ThompsonParams,
    dim: usize,
    arms: Vec<Arm>,
    rng: ChaCha8Rng,
}

#[derive(Serialize, Deserialize)]
struct State {
    arms: Vec<Arm>,
    rng_seed: [u8; 32],
    rng_stream: u64,
    /// u128 as a decimal string: JSON numbers stop at 64 bits.
    rng_word_pos: String,
}

impl LinearThompson {
    /// A policy over `n_arms` arms and `dim`-dimensional contexts.
    pub fn new(params: ThompsonParams, n_arms: usize, dim: usize, seed: u64) -> Result<Self> {
        params.validate()?;
        if n_arms == 0 || dim == 0 {
            return Err(HilError::invalid_input(
                "policy shape",
                format!("{n_arms} arms and dimension {dim}: both must be at least 1"),
            ));
        }
        Ok(Self {
            arms: vec![Arm::new(dim, params.lambda); n_arms],
            params,
            dim,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }
}

impl Policy for LinearThompson {
    fn name(&self) -> &str {
        NAME
    }
    fn n_arms(&self) -> usize {
        self.arms.len()
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }

    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        check_input(self, input)?;
        let x = input.context.as_slice();
        let scores: Vec<(f64, f64)> = self.arms.iter().map(|a| a.score(x)).collect();
        let v = self.params.v;
        let mut chosen = 0;
        let mut wins = 0usize;
        for s in 0..self.params.samples {
            let mut best = (f64::NEG_INFINITY, 0);
            for (i, (m, w)) in scores.iter().enumerate() {
                let draw = m + v * w * normal(&mut self.rng);
                if draw > best.0 {
                    best = (draw, i);
                }
            }
            if s == 0 {
                chosen = best.1;
            }
            wins += usize::from(best.1 == chosen);
        }
        let agreement = wins as f64 / self.params.samples as f64;
        // The agreement between posterior draws is this policy's own
        // quantity, not LinUCB-QG's gap: it goes in the extension map.
        let diagnostics = |forecast: Option<f64>| {
            Diagnostics::new()
                .with_arms(
                    scores
                        .iter()
                        .map(|&(m, w)| ArmDiagnostics::new(m, w, m + v * w))
                        .collect(),
                )
                .with_extra("agreement", agreement)
                .with_extra("confidence", self.params.confidence)
                .with_workload_forecast(forecast)
        };
        let arm = ArmId(chosen);
        if agreement < self.params.confidence {
            // Without a workload model the person's workload is not limited.
            let forecast = input.workload.if_queried(self.params.query).ok();
            if forecast.is_none_or(|wl| wl <= self.params.max_workload) {
                return Ok(
                    Decision::query(self.params.query, arm).with_diagnostics(diagnostics(forecast))
                );
            }
            return Ok(Decision::act(arm).with_diagnostics(diagnostics(forecast)));
        }
        Ok(Decision::act(arm).with_diagnostics(diagnostics(None)))
    }

    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        check_feedback(self, feedback)?;
        self.arms[feedback.arm.0].update(feedback.context.as_slice(), feedback.reward);
        Ok(())
    }

    fn save(&self) -> Result<Value> {
        let state = State {
            arms: self.arms.clone(),
            rng_seed: self.rng.get_seed(),
            rng_stream: self.rng.get_stream(),
            rng_word_pos: self.rng.get_word_pos().to_string(),
        };
        serde_json::to_value(state).map_err(|e| HilError::serde("linear_thompson state", e))
    }

    fn restore(&mut self, state: Value) -> Result<()> {
        let s: State = serde_json::from_value(state)
            .map_err(|e| HilError::serde("linear_thompson state", e))?;
        if s.arms.len() != self.arms.len()
            || s.arms
                .iter()
                .any(|a| a.b.len() != self.dim || a.a_inv.len() != self.dim * self.dim)
        {
            return Err(HilError::state(
                NAME,
                "the checkpoint is for a policy of another shape",
            ));
        }
        let word_pos: u128 = s
            .rng_word_pos
            .parse()
            .map_err(|e| HilError::serde("linear_thompson state: rng_word_pos", e))?;
        let mut rng = ChaCha8Rng::from_seed(s.rng_seed);
        rng.set_stream(s.rng_stream);
        rng.set_word_pos(word_pos);
        self.arms = s.arms;
        self.rng = rng;
        Ok(())
    }
}

/// The factory: parameters from `params`, shape and seed from `ctx`.
pub fn build(params: &Params, ctx: &TaskContext) -> Result<Box<dyn Policy>> {
    let p: ThompsonParams = params.parse(NAME)?;
    let (n_arms, dim) = (ctx.action_space().len(), ctx.context_dim());
    Ok(Box::new(LinearThompson::new(
        p,
        n_arms,
        dim,
        ctx.base().seed,
    )?))
}

/// Registers the policy type.
pub fn register(r: &mut Registrar<'_>) {
    r.policy(
        NAME,
        "linear Thompson sampling; asks when its posterior draws disagree on the best arm",
        build,
    );
}

hil_plugin::declare_plugin!(register);

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::ActionSpace;

    fn ctx() -> TaskContext {
        TaskContext::new(
            hil_config::BuildContext::new(".", 3),
            ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap(),
            5,
        )
    }

    // One test per property (checkpointing included: none is skipped).
    hil_conformance::conformance_tests! {
        policy linear_thompson {
            options: hil_conformance::CheckOptions::default().with_context_dim(5),
            make: |opts| build(&Params::empty(), &opts.task_context()),
        }
    }

    #[test]
    fn passes_the_whole_policy_suite_without_skipping() {
        let report = hil_conformance::check_policy(&|| build(&Params::empty(), &ctx())).unwrap();
        assert!(report.skipped.is_empty(), "{report:?}");
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = build(&Params::toml("v = -1.0"), &ctx()).err().unwrap();
        assert!(e.to_string().contains("`v`"), "{e}");
        let e = build(&Params::toml("vv = 1.0"), &ctx()).err().unwrap();
        assert!(e.to_string().contains("unknown field `vv`"), "{e}");
    }

    #[test]
    fn learns_the_better_arm_and_stops_asking() {
        let mut p = LinearThompson::new(ThompsonParams::default(), 2, 1, 1).unwrap();
        let x = hil_core::Context::new(vec![1.0]).unwrap();
        let history = hil_core::QueryHistory::new();
        for t in 1..=200 {
            let fb = Feedback::new(hil_core::Attempt {
                context: &x,
                arm: ArmId((t % 2) as usize),
                reward: if t % 2 == 1 { 1.0 } else { 0.0 },
                t,
            });
            p.observe(&fb).unwrap();
        }
        let input = DecisionInput::new(&x, 201, hil_core::WorkloadForecast::none(&history));
        let d = p.decide(&input).unwrap();
        assert_eq!(d.choice, hil_core::Choice::Act { arm: ArmId(1) });
    }
}
