//! Example downstream crate: a new assistive task added by depending on
//! hil-core statically, with no plugin involved.
//!
//! The task: **handing a cup to a person** who cannot reach far. For each
//! handover the robot picks a handover pose (one of five positions around
//! the person) or asks them where they want it. The context is the person's
//! posture (torso lean, reach of the dominant arm, seated height, which arm
//! is dominant) observed with noise. Which pose works depends on the
//! posture; the success probabilities are synthetic.
//!
//! Because the crate links hil-core statically, registering the config with
//! typetag is enough: `type = "cup_handover"` works in any experiment file
//! of a program that uses this crate (a program that names nothing of it
//! says `use hil_example_downstream_task as _;`, which links it).
//!
//! ```
//! use hil_config::EnvironmentConfig;
//! use hil_config::BuildContext;
//! use hil_example_downstream_task as _;
//! let cfg: Box<dyn EnvironmentConfig> = toml::from_str("type = \"cup_handover\"\nhandovers = 4").unwrap();
//! let env = cfg.build(&BuildContext::new(".", 0)).unwrap();
//! assert_eq!(env.action_space().len(), 5);
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use hil_config::BuildContext;
use hil_config::EnvironmentConfig;
use hil_core::{
    ActionSpace, ArmId, CallOrder, Context, Environment, HilError, Item, Outcome, Result,
};

/// Handover poses, in arm order.
pub const POSES: [&str; 5] = [
    "low_left",
    "low_centre",
    "chest_centre",
    "high_right",
    "low_right",
];

/// The environment config, named `cup_handover` in experiment files.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CupHandoverConfig {
    /// Handovers per episode (≥ 1).
    #[serde(default = "default_handovers")]
    pub handovers: usize,
}

fn default_handovers() -> usize {
    10
}

#[typetag::serde(name = "cup_handover")]
impl EnvironmentConfig for CupHandoverConfig {
    fn build(&self, _ctx: &BuildContext) -> Result<Box<dyn Environment>> {
        Ok(Box::new(CupHandover::new(self.handovers)?))
    }
}

/// The cup-handover task.
#[derive(Clone, Debug)]
pub struct CupHandover {
    handovers: usize,
    actions: ActionSpace,
    rng: ChaCha8Rng,
    next: usize,
    /// (item, posture features, success probability per pose)
    current: Option<(Item, [f64; 4], [f64; 5])>,
    calls: CallOrder,
}

impl CupHandover {
    /// `handovers` per episode.
    pub fn new(handovers: usize) -> Result<Self> {
        if handovers == 0 {
            return Err(HilError::invalid_parameter(
                "handovers",
                0,
                "must be at least 1",
            ));
        }
        Ok(Self {
            handovers,
            actions: ActionSpace::new(POSES)?,
            rng: ChaCha8Rng::seed_from_u64(0),
            next: 0,
            current: None,
            calls: CallOrder::new("cup_handover"),
        })
    }

    /// Success per pose for a posture: poses on the dominant side and within
    /// reach work; leaning forward favours low poses.
    fn probabilities(posture: &[f64; 4]) -> [f64; 5] {
        let [lean, reach, height, right_handed] = *posture;
        let side = |right: bool| {
            if (right_handed > 0.5) == right {
                0.25
            } else {
                -0.2
            }
        };
        let p = [
            0.45 + 0.3 * lean + side(false),
            0.55 + 0.2 * lean,
            0.35 + 0.4 * reach + 0.1 * height,
            0.15 + 0.5 * reach * height + side(true),
            0.45 + 0.3 * lean + side(true),
        ];
        p.map(|v| v.clamp(0.02, 0.98))
    }
}

impl Environment for CupHandover {
    fn name(&self) -> &str {
        "cup_handover"
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        4
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.current = None;
        self.calls.on_reset();
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        if self.next >= self.handovers {
            self.current = None;
            self.calls.on_next_item(false);
            return Ok(None);
        }
        let posture = [
            self.rng.random::<f64>(),
            self.rng.random::<f64>(),
            self.rng.random::<f64>(),
            f64::from(self.rng.random_bool(0.8)),
        ];
        let item = Item::new(self.next, "cup").with_description("a cup of water to hand over");
        self.next += 1;
        self.current = Some((item.clone(), posture, Self::probabilities(&posture)));
        self.calls.on_next_item(true);
        Ok(Some(item))
    }
    fn observe(&mut self) -> Result<Context> {
        self.calls.on_observe()?;
        let (_, posture, _) = self.current.as_ref().ok_or_else(|| {
            HilError::state("cup_handover", "no current handover: call next_item first")
        })?;
        let posture = *posture;
        let x: Vec<f64> = posture
            .iter()
            .map(|v| v + 0.05 * (self.rng.random::<f64>() - 0.5))
            .collect();
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        self.actions.check(arm)?;
        self.calls.on_execute()?;
        let p = self
            .current
            .as_ref()
            .ok_or_else(|| HilError::state("cup_handover", "no current handover"))?
            .2[arm.0];
        Ok(Outcome::new(self.rng.random_bool(p)).with_success_probability(p))
    }
    fn best_action(&self) -> Option<ArmId> {
        let p = self.current.as_ref()?.2;
        (0..p.len())
            .max_by(|a, b| p[*a].total_cmp(&p[*b]))
            .map(ArmId)
    }
    fn current_item(&self) -> Option<&Item> {
        self.current.as_ref().map(|c| &c.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy};
    use hil_core::channel::PerfectExpert;
    use hil_core::{Choice, QueryKind, Session, SessionSettings};
    use std::sync::Arc;

    #[test]
    fn passes_the_environment_conformance_suite() {
        hil_conformance::check_environment(
            &|| Ok(Box::new(CupHandover::new(6)?) as Box<dyn Environment>),
            3,
        )
        .unwrap();
    }

    #[test]
    fn runs_in_the_session_loop() {
        let mut env = CupHandover::new(5).unwrap();
        let mut policy = ScriptedPolicy::new(
            5,
            4,
            vec![Choice::Query {
                kind: QueryKind::default(),
                fallback: ArmId(0),
            }],
        );
        let mut channel = PerfectExpert::default();
        let mut session = Session::new(
            SessionSettings::default(),
            &mut env,
            &mut policy,
            &mut channel,
            Arc::new(CountingWorkload::new(0.01)),
        );
        let report = session.run_episode(3, &mut []).unwrap();
        assert_eq!(report.metrics.n_items, 5);
        // Always asking a perfect expert: every handover uses the best pose.
        assert!(report.metrics.n_q >= 5);
    }
}
