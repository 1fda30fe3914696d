//! Discrete session time.

use serde::{Deserialize, Serialize};

use crate::error::{HilError, Result};

/// A discrete timestep, counted from 1 at the first attempt of a session.
/// Timestep 0 is the start, where workload is `WL_0`.
pub type Timestep = u64;

/// The paper's timestep length, in seconds.
pub const DEFAULT_DT_SECONDS: f64 = 10.0;

/// Maps between discrete timesteps and seconds.
///
/// ```
/// use hil_core::TimeGrid;
/// let g = TimeGrid::default();
/// assert_eq!(g.step_of(35.0), 3);
/// assert_eq!(g.seconds_of(3), 30.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeGrid {
    /// Length of one timestep in seconds (Δt).
    pub dt_seconds: f64,
}

impl Default for TimeGrid {
    fn default() -> Self {
        Self {
            dt_seconds: DEFAULT_DT_SECONDS,
        }
    }
}

impl TimeGrid {
    /// A grid with step `dt_seconds` (must be finite and positive).
    pub fn new(dt_seconds: f64) -> Result<Self> {
        if !(dt_seconds.is_finite() && dt_seconds > 0.0) {
            return Err(HilError::invalid_parameter(
                "dt_seconds",
                dt_seconds,
                "must be finite and > 0",
            ));
        }
        Ok(Self { dt_seconds })
    }

    /// The timestep containing `seconds` (floor).
    pub fn step_of(&self, seconds: f64) -> Timestep {
        (seconds / self.dt_seconds).floor().max(0.0) as Timestep
    }

    /// The start of timestep `t` in seconds.
    pub fn seconds_of(&self, t: Timestep) -> f64 {
        t as f64 * self.dt_seconds
    }
}
