//! Errors of the MuJoCo feeding simulation.

use std::path::PathBuf;

use hil_core::HilError;

/// What can go wrong while loading or running the simulation.
#[derive(Debug, thiserror::Error)]
pub enum KinovaError {
    /// An action label is not a pitch family (VS, TV, TA) followed by a
    /// roll of 0 or 90 degrees.
    #[error(
        "action {name:?} is not a skewering action the simulator knows (VS, TV or TA followed by 0 or 90, e.g. TV90)"
    )]
    UnknownAction {
        /// The label.
        name: String,
    },
    /// The MJCF file does not exist or cannot be read.
    #[error("MJCF file {}: {source}", path.display())]
    MjcfUnreadable {
        /// The file concerned.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// MuJoCo rejected the MJCF (its message names the line and element).
    #[error("MJCF {origin}: MuJoCo could not load the model: {why}")]
    MjcfMalformed {
        /// File path, or `<built-in>`.
        origin: String,
        /// MuJoCo's message.
        why: String,
    },
    /// The model loads but lacks an element the simulation needs.
    #[error("MJCF {origin}: missing {kind} `{name}` (the feeding scene needs it)")]
    MjcfMissing {
        /// File path, or `<built-in>`.
        origin: String,
        /// Element kind (`body`, `joint`, `site`, ...).
        kind: &'static str,
        /// The name looked up.
        name: String,
    },
    /// An element exists but has the wrong shape (e.g. a food geom of the wrong type).
    #[error("MJCF {origin}: {what}")]
    MjcfInvalid {
        /// File path, or `<built-in>`.
        origin: String,
        /// What is wrong.
        what: String,
    },
    /// The physics diverged (non-finite state).
    #[error("simulation diverged at t = {time:.3} s during {phase}")]
    Diverged {
        /// Simulated time of the failure.
        time: f64,
        /// The controller phase.
        phase: &'static str,
    },
    /// Inverse kinematics found no joint configuration for a target pose.
    #[error("inverse kinematics failed for {what}: residual {residual:.4}")]
    IkFailed {
        /// The target concerned.
        what: String,
        /// Remaining pose error (m + rad).
        residual: f64,
    },
    /// A hold duration outside 0–60 s or not finite.
    #[error("hold of {seconds} s: must be finite and within 0–60 s")]
    InvalidHold {
        /// The value given.
        seconds: f64,
    },
    /// The step of the phases without cutting is not in (0, `MAX_DT`].
    #[error("free-phase step {seconds} s is not in (0, {max}] s")]
    InvalidFreeStep {
        /// The value given.
        seconds: f64,
        /// The longest step the skewering model tolerates.
        max: f64,
    },
}

impl From<KinovaError> for HilError {
    fn from(e: KinovaError) -> Self {
        // The simulator's error is kept as the source, so a caller can
        // downcast to it rather than parse the message.
        HilError::backend("mujoco", e.to_string()).with_source(e)
    }
}
