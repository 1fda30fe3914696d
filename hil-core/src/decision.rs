//! What a policy decides at one timestep, and why.

use serde::{Deserialize, Serialize};

use crate::action::ArmId;
use crate::context::Context;
use crate::query::QueryKind;

/// The choice a policy makes: act with a robot arm, or ask the human.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Choice {
    /// Execute a robot action autonomously.
    Act {
        /// The arm to execute.
        arm: ArmId,
    },
    /// Ask the human which action to use.
    Query {
        /// The kind of question to ask.
        kind: QueryKind,
        /// The arm the policy executes if the person declines or times out.
        fallback: ArmId,
    },
}

/// Per-arm numbers behind a decision, for logs and plots.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ArmDiagnostics {
    /// Estimated reward θᵀx.
    pub estimate: f64,
    /// Confidence width b(x) = sqrt(xᵀA⁻¹x), before scaling by α.
    pub bonus: f64,
    /// Upper confidence bound θᵀx + α·b(x).
    pub ucb: f64,
}

/// Why a policy decided what it did. Every field is optional so that
/// policies without a given quantity simply leave it out.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Diagnostics {
    /// One entry per arm, for estimator-based policies.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub arms: Vec<ArmDiagnostics>,
    /// The query gap G (LinUCB-QG).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// The threshold the gap was compared against (w·WL_t for LinUCB-QG).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
    /// The probability of querying (LinUCB-ExpDecay).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub query_probability: Option<f64>,
    /// The workload forecast the policy used, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub workload_forecast: Option<f64>,
}

/// A policy's decision with its diagnostics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Decision {
    /// The choice.
    pub choice: Choice,
    /// Why.
    pub diagnostics: Diagnostics,
}

impl Decision {
    /// A decision to act with `arm`, without diagnostics.
    pub fn act(arm: ArmId) -> Self {
        Self {
            choice: Choice::Act { arm },
            diagnostics: Diagnostics::default(),
        }
    }

    /// A decision to query with `kind`, falling back to `fallback`.
    pub fn query(kind: QueryKind, fallback: ArmId) -> Self {
        Self {
            choice: Choice::Query { kind, fallback },
            diagnostics: Diagnostics::default(),
        }
    }

    /// Attaches diagnostics.
    pub fn with_diagnostics(mut self, diagnostics: Diagnostics) -> Self {
        self.diagnostics = diagnostics;
        self
    }
}

/// The result of executing a robot action.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// Whether the attempt succeeded (the reward).
    pub success: bool,
    /// The probability that this action succeeds for this context, when the
    /// environment knows it (simulation). Metrics use it as the expected task
    /// reward r_task; otherwise they use `success` as 0/1.
    pub success_probability: Option<f64>,
}

impl Outcome {
    /// The reward as 0.0 / 1.0.
    pub fn reward(&self) -> f64 {
        if self.success { 1.0 } else { 0.0 }
    }

    /// The task reward r_task: the success probability if known, else the reward.
    pub fn task_reward(&self) -> f64 {
        self.success_probability.unwrap_or_else(|| self.reward())
    }
}

/// An offline observation: a context, the arm tried, and the reward seen.
/// Pretraining data for estimator-based policies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LabelledObservation {
    /// The context.
    pub context: Context,
    /// The arm that was tried.
    pub arm: ArmId,
    /// The reward observed (1 success, 0 failure, or a success probability).
    pub reward: f64,
}
