//! A simple counting workload model (`type = "demo_counting"`), for trying
//! the channels and the interaction record without a fitted model.
//!
//! It is deliberately simple and is not one of the paper's models (those are
//! in [`crate::models`]).

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use hil_config::BuildContext;
use hil_config::{WorkloadModelConfig, limits};
use hil_core::WorkloadInput;
use hil_core::{HilError, Result, WorkloadModel};

/// Config of the demo workload model, `type = "demo_counting"`:
///
/// ```toml
/// [workload]
/// type = "demo_counting"
/// increment = 0.05   # each query in the window adds this
/// window = 10        # timesteps a query keeps counting (H)
/// ```
///
/// ```
/// use hil_core::{QueryHistory, QueryKind, WorkloadInput, WorkloadModel};
/// use hil_workload::demo_counting::DemoCounting;
///
/// let model = DemoCounting { increment: 0.1, window: 10 };
/// let mut history = QueryHistory::new();
/// history.push(4, QueryKind::default())?;
/// assert!((model.predict(&WorkloadInput::new(0.5, &history, 5))? - 0.6).abs() < 1e-12);
/// # Ok::<(), hil_core::HilError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemoCounting {
    /// Workload added per query in the window, in [0, 1].
    pub increment: f64,
    /// Number of timesteps a query counts for (1 to
    /// [`limits::WINDOW`]).
    pub window: u64,
}

#[typetag::serde(name = "demo_counting")]
impl WorkloadModelConfig for DemoCounting {
    fn build(&self, _ctx: &BuildContext) -> Result<Arc<dyn WorkloadModel>> {
        self.validate()?;
        Ok(Arc::new(*self))
    }

    fn validate(&self) -> Result<()> {
        if !(0.0..=1.0).contains(&self.increment) {
            return Err(HilError::invalid_parameter(
                "increment",
                self.increment,
                "must be in [0, 1]",
            ));
        }
        limits::check_count("window", self.window, limits::WINDOW)
    }
}

/// WL_t = clamp(WL_0 + increment · (queries in the last `window` steps), 0, 1).
impl WorkloadModel for DemoCounting {
    fn name(&self) -> &str {
        "demo_counting"
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        let n = input.history.recent(input.t, self.window).count();
        Ok((input.wl0 + self.increment * n as f64).clamp(0.0, 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::{QueryHistory, QueryKind};

    #[test]
    fn the_demo_workload_conforms() {
        hil_conformance::check_workload_model(&DemoCounting {
            increment: 0.05,
            window: 10,
        })
        .unwrap();
    }

    #[test]
    fn queries_count_within_the_window_only() {
        let m = DemoCounting {
            increment: 0.1,
            window: 3,
        };
        let mut h = QueryHistory::new();
        h.push(1, QueryKind::default()).unwrap();
        h.push(2, QueryKind::default()).unwrap();
        assert!((m.predict(&WorkloadInput::new(0.2, &h, 2)).unwrap() - 0.4).abs() < 1e-12);
        assert!((m.predict(&WorkloadInput::new(0.2, &h, 10)).unwrap() - 0.2).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_are_rejected() {
        let ctx = BuildContext::new(".", 0);
        for bad in [
            DemoCounting {
                increment: 1.5,
                window: 3,
            },
            DemoCounting {
                increment: 0.1,
                window: 0,
            },
        ] {
            assert!(matches!(
                bad.build(&ctx),
                Err(HilError::InvalidParameter { .. })
            ));
        }
    }
}
