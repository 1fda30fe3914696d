//! Example plugin: a **noisy expert** query channel.
//!
//! A simulated person who knows the best action (the query's
//! `oracle_best`) but is not perfect: they decline with probability
//! `decline`, raised by `hard_decline` for hard questions or any
//! distraction, and otherwise answer a uniformly random *other* action with
//! probability `error`. Response times are drawn uniformly from
//! `response_time_s`, longer for hard questions.
//!
//! ```
//! use hil_plugin::Params;
//! use hil_core::ActionSpace;
//! use hil_config::{BuildContext, TaskContext};
//! let ctx = TaskContext::new(BuildContext::new(".", 1), ActionSpace::new(["a", "b"]).unwrap(), 4);
//! let ch = hil_example_channel_noisy_expert::build(
//!     &Params::toml("error = 0.2\ndecline = 0.1"), &ctx).unwrap();
//! assert_eq!(ch.name(), "noisy_expert");
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use hil_config::TaskContext;
use hil_core::{
    Answer, ArmId, Difficulty, Distraction, HilError, Query, QueryChannel, Response, Result,
};
use hil_plugin::{Params, Registrar};

/// The name the plugin registers.
pub const NAME: &str = "noisy_expert";

/// Parameters (all optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoisyExpertParams {
    /// Probability of answering a wrong action, in [0, 1].
    pub error: f64,
    /// Probability of declining an easy, undistracted question, in [0, 1].
    pub decline: f64,
    /// Added decline probability for a hard question or a distraction.
    pub hard_decline: f64,
    /// Response time range in seconds, `[min, max]`.
    pub response_time_s: [f64; 2],
}

impl Default for NoisyExpertParams {
    fn default() -> Self {
        Self {
            error: 0.1,
            decline: 0.05,
            hard_decline: 0.1,
            response_time_s: [2.0, 8.0],
        }
    }
}

/// The noisy expert.
#[derive(Clone, Debug)]
pub struct NoisyExpert {
    p: NoisyExpertParams,
    rng: ChaCha8Rng,
}

impl NoisyExpert {
    /// Validates the parameters.
    pub fn new(p: NoisyExpertParams, seed: u64) -> Result<Self> {
        for (name, v) in [
            ("error", p.error),
            ("decline", p.decline),
            ("hard_decline", p.hard_decline),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(HilError::invalid_parameter(name, v, "must be in [0, 1]"));
            }
        }
        let [lo, hi] = p.response_time_s;
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi) {
            return Err(HilError::invalid_parameter(
                "response_time_s",
                format!("[{lo}, {hi}]"),
                "must be finite with 0 ≤ min ≤ max",
            ));
        }
        Ok(Self {
            p,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }
}

impl QueryChannel for NoisyExpert {
    fn name(&self) -> &str {
        NAME
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn ask(&mut self, query: &Query) -> Result<Response> {
        let best = query.oracle_best.ok_or_else(|| {
            HilError::channel(
                NAME,
                "the simulated expert needs an environment that knows its best action",
            )
        })?;
        let n = query.actions.len();
        query.actions.check(best)?;
        let hard = query.kind.difficulty == Difficulty::Hard
            || query.kind.distraction != Distraction::None;
        let [lo, hi] = self.p.response_time_s;
        let slow = if query.kind.difficulty == Difficulty::Hard {
            1.5
        } else {
            1.0
        };
        let time = (lo + (hi - lo) * self.rng.random::<f64>()) * slow;
        let decline = (self.p.decline + if hard { self.p.hard_decline } else { 0.0 }).min(1.0);
        let r = if self.rng.random_bool(decline) {
            Response::without_action(Answer::Declined)
        } else if n > 1 && self.rng.random_bool(self.p.error) {
            // A wrong answer: any action but the best.
            let k = self.rng.random_range(0..n - 1);
            Response::action(ArmId(if k >= best.0 { k + 1 } else { k }))
        } else {
            Response::action(best)
        };
        Ok(r.with_response_time(time))
    }
}

/// The factory.
pub fn build(params: &Params, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
    Ok(Box::new(NoisyExpert::new(
        params.parse(NAME)?,
        ctx.base().seed,
    )?))
}

/// Registers the channel.
pub fn register(r: &mut Registrar<'_>) {
    r.query_channel(
        NAME,
        "a simulated expert who sometimes answers wrongly or declines",
        build,
    );
}

hil_plugin::declare_plugin!(register);

#[cfg(test)]
mod tests {
    use super::*;

    // One test per property; built through the factory, so seeded replay
    // is checked too.
    hil_conformance::conformance_tests! {
        query_channel noisy_expert {
            options: hil_conformance::CheckOptions::default().with_queries(60),
            make: |opts| build(&Params::empty(), &opts.task_context()),
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        let ctx = hil_conformance::CheckOptions::default().task_context();
        let e = build(&Params::toml("error = 1.5"), &ctx).err().unwrap();
        assert!(e.to_string().contains("`error`"), "{e}");
    }
}
