//! Simulated experts: people who know the best action (the paper's perfect
//! expert, [`hil_core::channel::PerfectExpert`]) but may err, decline and
//! take time to answer.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal};
use serde::{Deserialize, Serialize};

use hil_config::TaskContext;
use hil_config::{QueryChannelConfig, limits};
use hil_core::channel::PerfectExpert;
use hil_core::session::splitmix;
use hil_core::{
    Answer, ArmId, BoundingBox, HilError, Query, QueryChannel, Response, ResponseType, Result,
};

/// Largest log-space spread of simulated response times: with it, a draw
/// 30 standard deviations out from a one-day median is still finite.
pub const MAX_SIGMA: f64 = 10.0;

/// How long a simulated person takes to answer: log-normal with the given
/// median and log-space spread (`sigma = 0` gives a fixed time).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResponseTimeModel {
    /// Median response time in seconds, in (0, [`limits::SECONDS`]].
    pub median_s: f64,
    /// Standard deviation of the log response time, in [0, [`MAX_SIGMA`]].
    #[serde(default)]
    pub sigma: f64,
}

impl ResponseTimeModel {
    fn validate(&self) -> Result<()> {
        limits::check_seconds("response_time.median_s", self.median_s)?;
        // A log-space spread beyond a few units makes a day-long median
        // answer in seconds or in millennia; beyond MAX_SIGMA a draw can
        // overflow to an infinite time.
        if !(self.sigma.is_finite() && (0.0..=MAX_SIGMA).contains(&self.sigma)) {
            return Err(HilError::invalid_parameter(
                "response_time.sigma",
                self.sigma,
                format!("must be a number in [0, {MAX_SIGMA}]"),
            ));
        }
        Ok(())
    }

    fn sample(&self, rng: &mut ChaCha8Rng) -> f64 {
        if self.sigma == 0.0 {
            return self.median_s;
        }
        // Validated parameters make the distribution well-defined.
        match LogNormal::new(self.median_s.ln(), self.sigma) {
            Ok(d) => d.sample(rng),
            Err(_) => self.median_s,
        }
    }
}

/// Parameters of a [`SimulatedExpert`]; also its config, named
/// `simulated_expert` in experiment files:
///
/// ```toml
/// [channel]
/// type = "simulated_expert"
/// error_rate = 0.1      # answers a wrong action 10% of the time
/// decline_rate = 0.05   # says "I don't know" 5% of the time
/// response_time = { median_s = 4.0, sigma = 0.5 }
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatedExpertConfig {
    /// Probability in [0, 1] that an answer names a wrong action (uniform
    /// over the other actions).
    #[serde(default)]
    pub error_rate: f64,
    /// Probability in [0, 1] that the expert declines to answer.
    #[serde(default)]
    pub decline_rate: f64,
    /// Simulated response times; none are reported when absent.
    #[serde(default)]
    pub response_time: Option<ResponseTimeModel>,
}

impl SimulatedExpertConfig {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("error_rate", self.error_rate),
            ("decline_rate", self.decline_rate),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(HilError::invalid_parameter(
                    name,
                    v,
                    "must be a probability in [0, 1]",
                ));
            }
        }
        if let Some(rt) = &self.response_time {
            rt.validate()?;
        }
        Ok(())
    }
}

#[typetag::serde(name = "simulated_expert")]
impl QueryChannelConfig for SimulatedExpertConfig {
    fn build(&self, _ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        Ok(Box::new(SimulatedExpert::new(self.clone())?))
    }

    fn validate(&self) -> Result<()> {
        SimulatedExpertConfig::validate(self)
    }
}

/// A simulated person who knows the best action and answers every query,
/// as in the paper's simulations, possibly with errors, declines and
/// response times.
///
/// The truth comes from the one perfect expert,
/// [`hil_core::channel::PerfectExpert`] (the environment's known best
/// action): with default parameters (the `simulated_expert` config with no
/// fields) a simulated expert always names that action, and so is the
/// paper's perfect expert. Use `PerfectExpert` itself where the answer's
/// shape and timing do not matter.
///
/// As in the paper, the response type only changes how much workload a
/// query costs: whatever the type, the simulated answer determines the
/// action (an MCQ answer names it, a bounding-box or open-ended answer is
/// taken to carry the information that identifies it).
///
/// Each answer is drawn from its own random stream derived from the seed and
/// the query's timestep, so skipping or replaying a query never shifts the
/// answers to later ones (resuming a recorded session relies on this).
///
/// ```
/// use hil_channels::{SimulatedExpert, SimulatedExpertConfig};
/// let mut perfect = SimulatedExpert::new(SimulatedExpertConfig::default()).unwrap();
/// hil_conformance::check_query_channel(&mut perfect, 18).unwrap();
/// let noisy = SimulatedExpert::new(SimulatedExpertConfig { error_rate: 0.2, ..Default::default() });
/// assert!(noisy.is_ok());
/// ```
#[derive(Clone, Debug)]
pub struct SimulatedExpert {
    params: SimulatedExpertConfig,
    seed: u64,
    truth: PerfectExpert,
}

impl SimulatedExpert {
    /// An expert with validated parameters.
    pub fn new(params: SimulatedExpertConfig) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            seed: 0,
            truth: PerfectExpert::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &SimulatedExpertConfig {
        &self.params
    }
}

impl QueryChannel for SimulatedExpert {
    fn name(&self) -> &str {
        "simulated_expert"
    }

    fn seed(&mut self, seed: u64) {
        self.seed = seed;
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        // The perfect expert checks that the environment knows its best
        // action and that it indexes the action space.
        let Response {
            expert_arm: Some(best),
            ..
        } = self.truth.ask(query)?
        else {
            return Err(HilError::channel(
                self.name(),
                "the perfect expert named no action",
            ));
        };
        let mut rng = ChaCha8Rng::seed_from_u64(splitmix(self.seed, query.t));
        // Draw every random quantity unconditionally, in a fixed order, so
        // that changing one rate does not reshuffle the others.
        let declines = rng.random_bool(self.params.decline_rate);
        let errs = rng.random_bool(self.params.error_rate);
        let other = rng.random_range(0..query.actions.len().max(2) - 1);
        let jitter: [f64; 4] = std::array::from_fn(|_| rng.random_range(-0.05..0.05));
        let response_time_s = self.params.response_time.map(|m| m.sample(&mut rng));

        if declines {
            return Ok(Response::new(Answer::Declined, None, response_time_s));
        }
        let arm = if errs && query.actions.len() > 1 {
            // Uniform over the actions other than the best one.
            ArmId(if other >= best.0 { other + 1 } else { other })
        } else {
            best
        };
        let answer = match query.kind.response {
            ResponseType::Mcq => Answer::Action { arm },
            ResponseType::BoundingBox => Answer::BoundingBox {
                bbox: BoundingBox::new(
                    0.35 + jitter[0],
                    0.35 + jitter[1],
                    0.65 + jitter[2],
                    0.65 + jitter[3],
                ),
            },
            ResponseType::OpenEnded => Answer::Text {
                text: format!("try {}", query.actions.name(arm)?),
            },
        };
        Ok(Response::new(answer, Some(arm), response_time_s))
    }
}
