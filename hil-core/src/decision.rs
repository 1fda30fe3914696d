//! What a policy decides at one timestep, and why.

use std::collections::BTreeMap;

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
#[non_exhaustive]
pub struct ArmDiagnostics {
    /// Estimated reward θᵀx.
    pub estimate: f64,
    /// Confidence width b(x) = sqrt(xᵀA⁻¹x), before scaling by α.
    pub bonus: f64,
    /// Upper confidence bound θᵀx + α·b(x).
    pub ucb: f64,
}

impl ArmDiagnostics {
    /// An arm's estimate, confidence width and upper bound.
    pub fn new(estimate: f64, bonus: f64, ucb: f64) -> Self {
        Self {
            estimate,
            bonus,
            ucb,
        }
    }
}

/// A component's own named numbers, for what the shared fields do not
/// name: a Thompson-sampling policy's agreement between posterior draws, an
/// environment's contact force. Logged with the step, checked to be finite
/// by the session loop, and never read by hil's own code, so a new quantity
/// needs no change to hil.
///
/// ```
/// use hil_core::Extras;
/// let x = Extras::new().with("agreement", 0.8);
/// assert_eq!(x.get("agreement"), Some(0.8));
/// assert_eq!(x.get("gap"), None);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Extras(BTreeMap<String, f64>);

impl Extras {
    /// No values.
    pub fn new() -> Self {
        Self::default()
    }

    /// These values and `name` = `value` (replacing an earlier one).
    pub fn with(mut self, name: impl Into<String>, value: f64) -> Self {
        self.insert(name, value);
        self
    }

    /// Sets `name` to `value`.
    pub fn insert(&mut self, name: impl Into<String>, value: f64) {
        self.0.insert(name.into(), value);
    }

    /// The value under `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.get(name).copied()
    }

    /// The values in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.0.iter().map(|(k, v)| (k.as_str(), *v))
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// Why a policy decided what it did. Every field is optional so that
/// policies without a given quantity simply leave it out; a policy's own
/// quantities go in [`Diagnostics::extra`], never in a field that means
/// something else.
///
/// ```
/// use hil_core::Diagnostics;
/// let d = Diagnostics::new().with_gap(0.4).with_threshold(0.1).with_extra("agreement", 0.9);
/// assert_eq!((d.gap, d.extra.get("agreement")), (Some(0.4), Some(0.9)));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
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
    /// The policy's own quantities.
    #[serde(default, skip_serializing_if = "Extras::is_empty")]
    pub extra: Extras,
}

impl Diagnostics {
    /// No diagnostics.
    pub fn new() -> Self {
        Self::default()
    }

    /// With per-arm numbers.
    pub fn with_arms(mut self, arms: Vec<ArmDiagnostics>) -> Self {
        self.arms = arms;
        self
    }

    // The builders of optional fields take `impl Into<Option<f64>>`: a
    // value sets the field, `None` clears it, and a caller holding an
    // `Option` passes it as it is (one convention for every builder).

    /// With the query gap G.
    pub fn with_gap(mut self, gap: impl Into<Option<f64>>) -> Self {
        self.gap = gap.into();
        self
    }

    /// With the threshold the gap was compared against.
    pub fn with_threshold(mut self, threshold: impl Into<Option<f64>>) -> Self {
        self.threshold = threshold.into();
        self
    }

    /// With the probability of querying.
    pub fn with_query_probability(mut self, p: impl Into<Option<f64>>) -> Self {
        self.query_probability = p.into();
        self
    }

    /// With the workload forecast used (none if `None`).
    ///
    /// ```
    /// use hil_core::Diagnostics;
    /// let d = Diagnostics::new().with_gap(0.2).with_workload_forecast(Some(0.4));
    /// assert_eq!((d.gap, d.workload_forecast), (Some(0.2), Some(0.4)));
    /// assert_eq!(d.with_gap(None).gap, None);
    /// ```
    pub fn with_workload_forecast(mut self, forecast: impl Into<Option<f64>>) -> Self {
        self.workload_forecast = forecast.into();
        self
    }

    /// With one of the policy's own quantities.
    pub fn with_extra(mut self, name: impl Into<String>, value: f64) -> Self {
        self.extra.insert(name, value);
        self
    }

    /// The first field that is not a finite number, by its path
    /// (`arms[1].ucb`, `gap`, `extra.agreement`), with its value. The one
    /// definition the session loop and the conformance suite both check;
    /// it allocates only to name a bad field.
    ///
    /// ```
    /// use hil_core::{ArmDiagnostics, Diagnostics};
    /// let d = Diagnostics::new().with_arms(vec![ArmDiagnostics::new(0.5, 0.1, 0.6); 2]);
    /// assert_eq!(d.first_non_finite(), None);
    /// let d = d.with_gap(f64::NAN);
    /// assert_eq!(d.first_non_finite().map(|(field, _)| field).as_deref(), Some("gap"));
    /// ```
    pub fn first_non_finite(&self) -> Option<(String, f64)> {
        for (i, a) in self.arms.iter().enumerate() {
            for (name, v) in [("estimate", a.estimate), ("bonus", a.bonus), ("ucb", a.ucb)] {
                if !v.is_finite() {
                    return Some((format!("arms[{i}].{name}"), v));
                }
            }
        }
        for (name, v) in [
            ("gap", self.gap),
            ("threshold", self.threshold),
            ("query_probability", self.query_probability),
            ("workload_forecast", self.workload_forecast),
        ] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Some((name.to_string(), v));
            }
        }
        self.extra
            .iter()
            .find(|(_, v)| !v.is_finite())
            .map(|(name, v)| (format!("extra.{name}"), v))
    }
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
///
/// ```
/// use hil_core::Outcome;
/// let o = Outcome::new(true).with_success_probability(0.7).with_extra("force_n", 2.5);
/// assert_eq!((o.reward(), o.task_reward(), o.extra.get("force_n")), (1.0, 0.7, Some(2.5)));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Outcome {
    /// Whether the attempt succeeded (the reward).
    pub success: bool,
    /// The probability that this action succeeds for this context, when the
    /// environment knows it (simulation). Metrics use it as the expected task
    /// reward r_task; otherwise they use `success` as 0/1.
    pub success_probability: Option<f64>,
    /// The environment's own quantities (e.g. a simulator's contact force).
    #[serde(default, skip_serializing_if = "Extras::is_empty")]
    pub extra: Extras,
}

impl Outcome {
    /// A success or failure whose probability is not known.
    pub fn new(success: bool) -> Self {
        Self {
            success,
            success_probability: None,
            extra: Extras::default(),
        }
    }

    /// With the probability that the action succeeds in this context
    /// (`None`: not known).
    pub fn with_success_probability(mut self, p: impl Into<Option<f64>>) -> Self {
        self.success_probability = p.into();
        self
    }

    /// With one of the environment's own quantities.
    pub fn with_extra(mut self, name: impl Into<String>, value: f64) -> Self {
        self.extra.insert(name, value);
        self
    }

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
