//! Example plugin: a **fatigue** workload model.
//!
//! Fatigue F builds with every query and recovers between them:
//! - between queries it decays, F(t) = F(t_q)·exp(−(t − t_q)/τ);
//! - a query of kind k at t_q adds cost(k)·(1 + build·F), so queries asked
//!   on an already tired person cost more;
//! - WL_t = clamp(WL_0 + F(t), 0, 1).
//!
//! cost(k) = `base` × the response-type, difficulty and distraction factors
//! (all ≥ 0, so a query never lowers workload). Time is in session timesteps
//! (Δt = 10 s), so the default τ = 12 recovers by 1/e in two minutes.
//!
//! ```
//! use hil_core::{QueryHistory, QueryKind, WorkloadInput, WorkloadModel};
//! use hil_example_workload_fatigue::{Fatigue, FatigueParams};
//! let m = Fatigue::new(FatigueParams::default()).unwrap();
//! let mut h = QueryHistory::new();
//! h.push(1, QueryKind::default()).unwrap();
//! let just_after = m.predict(&WorkloadInput::new(0.3, &h, 1)).unwrap();
//! let later = m.predict(&WorkloadInput::new(0.3, &h, 40)).unwrap();
//! assert!(just_after > later && later > 0.3);
//! ```

use serde::{Deserialize, Serialize};

use hil_config::BuildContext;
use hil_core::WorkloadInput;
use hil_core::workload::check_wl0;
use hil_core::{
    Difficulty, Distraction, HilError, QueryHistory, QueryKind, ResponseType, Result, Timestep,
    WorkloadModel,
};
use hil_plugin::{Params, Registrar};

/// The name the plugin registers.
pub const NAME: &str = "fatigue";

/// Parameters (all optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FatigueParams {
    /// Recovery time constant τ in timesteps (> 0).
    pub tau: f64,
    /// Cost of an easy multiple-choice query without distraction (≥ 0).
    pub base: f64,
    /// How much existing fatigue amplifies a new query's cost (≥ 0).
    pub build: f64,
    /// Cost factors for multiple choice, bounding box, open-ended (≥ 0).
    pub response: [f64; 3],
    /// Cost factor of a hard question (≥ 0; easy is 1).
    pub hard: f64,
    /// Cost factors for no, easy and hard distraction (≥ 0).
    pub distraction: [f64; 3],
}

impl Default for FatigueParams {
    fn default() -> Self {
        Self {
            tau: 12.0,
            base: 0.06,
            build: 0.5,
            response: [1.0, 1.3, 1.6],
            hard: 1.4,
            distraction: [1.0, 1.2, 1.5],
        }
    }
}

/// The fatigue model.
#[derive(Clone, Debug)]
pub struct Fatigue {
    p: FatigueParams,
}

impl Fatigue {
    /// Validates the parameters.
    pub fn new(p: FatigueParams) -> Result<Self> {
        if !(p.tau.is_finite() && p.tau > 0.0) {
            return Err(HilError::invalid_parameter(
                "tau",
                p.tau,
                "must be finite and > 0",
            ));
        }
        let factors = [("base", p.base), ("build", p.build), ("hard", p.hard)]
            .into_iter()
            .chain(p.response.iter().map(|v| ("response", *v)))
            .chain(p.distraction.iter().map(|v| ("distraction", *v)));
        for (name, v) in factors {
            if !(v.is_finite() && v >= 0.0) {
                return Err(HilError::invalid_parameter(
                    name,
                    v,
                    "must be finite and ≥ 0",
                ));
            }
        }
        Ok(Self { p })
    }

    fn cost(&self, k: QueryKind) -> f64 {
        let r = match k.response {
            ResponseType::Mcq => self.p.response[0],
            ResponseType::BoundingBox => self.p.response[1],
            ResponseType::OpenEnded => self.p.response[2],
        };
        let d = match k.difficulty {
            Difficulty::Easy => 1.0,
            Difficulty::Hard => self.p.hard,
        };
        let x = match k.distraction {
            Distraction::None => self.p.distraction[0],
            Distraction::Easy => self.p.distraction[1],
            Distraction::Hard => self.p.distraction[2],
        };
        self.p.base * r * d * x
    }

    /// Fatigue at `t` after the queries asked up to `t`.
    pub fn fatigue(&self, history: &QueryHistory, t: Timestep) -> f64 {
        let mut f = 0.0;
        let mut last = 0;
        for q in history.records().iter().take_while(|q| q.t <= t) {
            f *= (-((q.t - last) as f64) / self.p.tau).exp();
            f += self.cost(q.kind) * (1.0 + self.p.build * f);
            last = q.t;
        }
        f * (-((t.saturating_sub(last)) as f64) / self.p.tau).exp()
    }
}

impl WorkloadModel for Fatigue {
    fn name(&self) -> &str {
        NAME
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        check_wl0(input.wl0)?;
        Ok((input.wl0 + self.fatigue(input.history, input.t)).clamp(0.0, 1.0))
    }
}

/// The factory.
pub fn build(params: &Params, _ctx: &BuildContext) -> Result<Box<dyn WorkloadModel>> {
    Ok(Box::new(Fatigue::new(params.parse(NAME)?)?))
}

/// Registers the model.
pub fn register(r: &mut Registrar<'_>) {
    r.workload_model(
        NAME,
        "fatigue that builds with each query and recovers between them",
        build,
    );
}

hil_plugin::declare_plugin!(register);

#[cfg(test)]
mod tests {
    use super::*;

    // One test per property.
    hil_conformance::conformance_tests! {
        workload_model fatigue {
            options: hil_conformance::CheckOptions::default(),
            make: |opts| build(&Params::empty(), &opts.build_context()),
        }
    }

    #[test]
    fn fatigue_compounds_and_recovers() {
        let m = Fatigue::new(FatigueParams::default()).unwrap();
        let mut h = QueryHistory::new();
        h.push(1, QueryKind::default()).unwrap();
        let one = m.fatigue(&h, 1);
        assert!((one - 0.06).abs() < 1e-12);
        h.push(1, QueryKind::default()).unwrap();
        // The second query at the same time costs more: the person is tired.
        assert!(m.fatigue(&h, 1) - one > 0.06);
        assert!(m.fatigue(&h, 100) < 1e-3);
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = build(&Params::json(r#"{"tau": 0}"#), &BuildContext::new(".", 0))
            .err()
            .unwrap();
        assert!(e.to_string().contains("`tau`"), "{e}");
    }
}
