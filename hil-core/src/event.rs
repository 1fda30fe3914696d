//! The typed record of one session step, consumed by metrics, logs and plots.

use serde::{Deserialize, Serialize};

use crate::action::ArmId;
use crate::context::Context;
use crate::decision::{Diagnostics, Outcome};
use crate::query::{QueryKind, Response};
use crate::time::Timestep;

/// How the arm of a step was chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum StepDecision {
    /// The policy acted autonomously.
    Act {
        /// The arm it chose.
        arm: ArmId,
    },
    /// The policy asked the human at this step.
    Query {
        /// What was asked.
        kind: QueryKind,
        /// The arm the policy would have used without an answer.
        fallback: ArmId,
    },
    /// An earlier query at this item is being followed: the expert's arm is
    /// executed again and the policy was not consulted.
    FollowExpert {
        /// The expert's arm.
        arm: ArmId,
    },
}

impl StepDecision {
    /// True for a step at which a query was asked.
    pub fn is_query(&self) -> bool {
        matches!(self, Self::Query { .. })
    }
}

/// A step that has been decided but not yet executed. Observers receive it
/// before the robot acts, so that a log can reach the disk first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PendingStep {
    /// Session timestep (1-based).
    pub t: Timestep,
    /// Index of the item in the episode.
    pub item_index: usize,
    /// The item's type.
    pub item_label: String,
    /// Attempt number at this item (0-based).
    pub attempt: u32,
    /// The observed context.
    pub context: Context,
    /// How the arm was chosen.
    pub decision: StepDecision,
    /// The policy's diagnostics, when it was consulted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diagnostics: Option<Diagnostics>,
    /// The human's response, at a query step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub response: Option<Response>,
    /// The arm that is executed.
    pub arm: ArmId,
    /// The workload trace: WL_t = f(WL_0, Q_t) at this step under the
    /// session's workload model, counting this step's query if any
    /// ([`crate::workload::workload_at`]). The last step's value is the
    /// episode's WL_T.
    pub wl_t: f64,
}

/// One completed step of a session.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepEvent {
    /// Everything known before execution.
    #[serde(flatten)]
    pub step: PendingStep,
    /// What happened.
    pub outcome: Outcome,
}

impl StepEvent {
    /// The expected task reward r_task of this step.
    pub fn task_reward(&self) -> f64 {
        self.outcome.task_reward()
    }
}
