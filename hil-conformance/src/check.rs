//! The names of the conformance checks, with what usually breaks each one
//! and how to fix it (shown with every failure, as Gymnasium's `check_env`
//! does).

/// The trait a check belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Subject {
    /// [`hil_core::Policy`].
    Policy,
    /// [`hil_core::Environment`].
    Environment,
    /// [`hil_core::WorkloadModel`].
    WorkloadModel,
    /// [`hil_core::QueryChannel`].
    QueryChannel,
}

/// One conformance check. Tests match on these, never on message text.
///
/// Most checks are *properties*: a failure of one is independent of the
/// others, and [`crate::conformance_tests!`] generates one `#[test]` per
/// property. A few are *prerequisites* (the object builds, calls with valid
/// input succeed) that every property needs on the way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Check {
    /// The factory builds an object (prerequisite of every property).
    Build,

    /// Policy: at least one arm and dimension, equal to the options' action
    /// space and context dimension, and equal across instances.
    PolicyShape,
    /// Policy: `decide` and `observe` succeed on valid input (prerequisite).
    PolicyDecides,
    /// Policy: every decision's arm (acted or fallback) indexes the arms.
    ArmInRange,
    /// Policy: diagnostics are finite, bonuses non-negative.
    FiniteDiagnostics,
    /// Policy: per-arm diagnostics are empty or cover every arm.
    DiagnosticsCoverArms,
    /// Policy: two instances seeded alike decide alike on the same inputs.
    Determinism,
    /// Policy: a context of another dimension (longer or shorter) is
    /// refused with [`hil_core::HilError::DimensionMismatch`].
    RejectsWrongDimension,
    /// Policy: feedback for an arm outside the action space is refused with
    /// [`hil_core::HilError::ArmOutOfRange`].
    RejectsArmOutOfRange,
    /// Policy: after refusing bad input the policy decides exactly as an
    /// instance that never saw it.
    RejectionHasNoEffect,
    /// Policy: `restore(save())` into a fresh instance continues identically
    /// (skipped only if a fresh instance's `save` says it cannot checkpoint).
    Checkpoint,

    /// Environment: a non-empty action space and a positive context dimension.
    EnvironmentShape,
    /// Environment: `reset`, `next_item`, `observe` and `execute` succeed in
    /// order (prerequisite).
    EpisodeRuns,
    /// Environment: an episode has at least one item.
    EpisodeHasItems,
    /// Environment: an episode ends within 10,000 items.
    EpisodesEnd,
    /// Environment: `current_item` returns what `next_item` returned.
    CurrentItem,
    /// Environment: contexts have the declared dimension.
    ContextDimension,
    /// Environment: success probabilities lie in [0, 1].
    SuccessProbability,
    /// Environment: `best_action` indexes the action space.
    BestActionInRange,
    /// Environment: the same seed replays the same items, contexts and
    /// outcomes, on another instance and after another `reset`.
    Replayable,
    /// Environment: `execute` of an arm outside the action space is refused
    /// with [`hil_core::HilError::ArmOutOfRange`] and leaves the attempt intact.
    ExecuteRejectsArmOutOfRange,
    /// Environment: calls out of order are refused with
    /// [`hil_core::HilError::State`] and a later `reset` still replays.
    OutOfOrderCalls,

    /// Workload model: `predict` succeeds on valid input (prerequisite).
    Predicts,
    /// Workload model: an empty history at t = 0 gives a finite prediction.
    EmptyHistory,
    /// Workload model: predictions are finite.
    FinitePrediction,
    /// Workload model: repeated calls return the same bits.
    DeterministicPrediction,
    /// Workload model: `predict_if_queried` equals `predict` on the history
    /// with the query appended.
    Counterfactual,

    /// Query channel: `ask` answers (prerequisite).
    Answers,
    /// Query channel: the expert arm indexes the query's actions.
    ExpertArmInRange,
    /// Query channel: response times are finite and non-negative.
    ResponseTime,
    /// Query channel: an `Action` answer's arm is the expert arm.
    AnswerConsistent,
    /// Query channel: two instances seeded alike answer the same queries alike.
    SeededReplay,

    /// Every trait: no object the suite built panics when it is dropped
    /// (a plugin's guard catches such a panic and hands it to the host).
    Destructor,
}

impl Check {
    /// Every check, in the order the suites run them.
    pub const ALL: &'static [Check] = &[
        Check::Build,
        Check::PolicyShape,
        Check::PolicyDecides,
        Check::ArmInRange,
        Check::FiniteDiagnostics,
        Check::DiagnosticsCoverArms,
        Check::Determinism,
        Check::RejectsWrongDimension,
        Check::RejectsArmOutOfRange,
        Check::RejectionHasNoEffect,
        Check::Checkpoint,
        Check::EnvironmentShape,
        Check::EpisodeRuns,
        Check::EpisodeHasItems,
        Check::EpisodesEnd,
        Check::CurrentItem,
        Check::ContextDimension,
        Check::SuccessProbability,
        Check::BestActionInRange,
        Check::Replayable,
        Check::ExecuteRejectsArmOutOfRange,
        Check::OutOfOrderCalls,
        Check::Predicts,
        Check::EmptyHistory,
        Check::FinitePrediction,
        Check::DeterministicPrediction,
        Check::Counterfactual,
        Check::Answers,
        Check::ExpertArmInRange,
        Check::ResponseTime,
        Check::AnswerConsistent,
        Check::SeededReplay,
        Check::Destructor,
    ];

    /// The checks of `subject` that are properties (not prerequisites), in
    /// the order the suite runs them: one generated test each.
    pub fn properties(subject: Subject) -> Vec<Check> {
        Self::ALL
            .iter()
            .copied()
            .filter(|c| c.applies_to(subject) && !c.is_prerequisite())
            .collect()
    }

    /// Whether the suite of `subject` runs this check.
    pub fn applies_to(self, subject: Subject) -> bool {
        match self {
            Check::Build | Check::Destructor => true,
            other => other.subject() == Some(subject),
        }
    }

    /// Whether every property needs this check on the way (so it is never
    /// filtered out when one property runs alone).
    pub fn is_prerequisite(self) -> bool {
        matches!(
            self,
            Check::Build
                | Check::PolicyDecides
                | Check::EpisodeRuns
                | Check::Predicts
                | Check::Answers
        )
    }

    /// The trait the check belongs to (`None` for [`Check::Build`] and
    /// [`Check::Destructor`], which every suite runs: see
    /// [`Check::applies_to`]).
    pub fn subject(self) -> Option<Subject> {
        use Check::*;
        Some(match self {
            Build | Destructor => return None,
            PolicyShape
            | PolicyDecides
            | ArmInRange
            | FiniteDiagnostics
            | DiagnosticsCoverArms
            | Determinism
            | RejectsWrongDimension
            | RejectsArmOutOfRange
            | RejectionHasNoEffect
            | Checkpoint => Subject::Policy,
            EnvironmentShape
            | EpisodeRuns
            | EpisodeHasItems
            | EpisodesEnd
            | CurrentItem
            | ContextDimension
            | SuccessProbability
            | BestActionInRange
            | Replayable
            | ExecuteRejectsArmOutOfRange
            | OutOfOrderCalls => Subject::Environment,
            Predicts
            | EmptyHistory
            | FinitePrediction
            | DeterministicPrediction
            | Counterfactual => Subject::WorkloadModel,
            Answers | ExpertArmInRange | ResponseTime | AnswerConsistent | SeededReplay => {
                Subject::QueryChannel
            }
        })
    }

    /// The check's name, as reports and generated tests show it.
    pub fn name(self) -> &'static str {
        use Check::*;
        match self {
            Build => "build",
            PolicyShape => "shape",
            PolicyDecides => "decide and observe succeed",
            ArmInRange => "arm in range",
            FiniteDiagnostics => "finite diagnostics",
            DiagnosticsCoverArms => "diagnostics cover every arm",
            Determinism => "determinism",
            RejectsWrongDimension => "rejects wrong dimension",
            RejectsArmOutOfRange => "rejects arm out of range",
            RejectionHasNoEffect => "rejection has no effect",
            Checkpoint => "checkpoint",
            EnvironmentShape => "shape",
            EpisodeRuns => "episode runs",
            EpisodeHasItems => "episode has items",
            EpisodesEnd => "episodes end",
            CurrentItem => "current item",
            ContextDimension => "context dimension",
            SuccessProbability => "success probability in [0, 1]",
            BestActionInRange => "best action in range",
            Replayable => "replayable",
            ExecuteRejectsArmOutOfRange => "execute rejects arm out of range",
            OutOfOrderCalls => "out-of-order calls",
            Predicts => "predict succeeds",
            EmptyHistory => "empty history",
            FinitePrediction => "finite",
            DeterministicPrediction => "deterministic",
            Counterfactual => "counterfactual",
            Answers => "ask answers",
            ExpertArmInRange => "expert arm in range",
            ResponseTime => "response time",
            AnswerConsistent => "answer consistent",
            SeededReplay => "seeded replay",
            Destructor => "drop does not panic",
        }
    }

    /// What usually breaks this check, and the fix.
    pub fn hint(self) -> &'static str {
        use Check::*;
        match self {
            Build => {
                "the factory refused its parameters or its context; check the parameters it was given (`--params` for `hil plugins check`), and that a policy or query channel reads the action space and context dimension from its TaskContext (ctx.action_space(), ctx.context_dim())"
            }
            PolicyShape => {
                "the policy sizes itself from something other than its TaskContext; take n_arms from ctx.action_space().len() and dim from ctx.context_dim()"
            }
            PolicyDecides => {
                "decide or observe failed on valid input; validate with hil_core::policy::check_input/check_feedback and do not error on ordinary values"
            }
            ArmInRange => {
                "a decision names an arm outside 0..n_arms (often an off-by-one or a fixed arm count); choose among 0..self.n_arms(), for the query fallback too"
            }
            FiniteDiagnostics => {
                "an estimate, bonus or score is NaN or infinite (a division by a zero count, a log of 0); guard the arithmetic, keep bonuses >= 0"
            }
            DiagnosticsCoverArms => {
                "Diagnostics::arms has an entry count other than n_arms; fill one entry per arm, or leave it empty"
            }
            Determinism => {
                "the policy uses randomness not derived from Policy::seed (thread_rng, time, HashMap order); draw from an RNG seeded in seed()"
            }
            RejectsWrongDimension => {
                "the policy indexes its weights with the context without checking its length (a longer context panics, a shorter one is silently accepted); call hil_core::policy::check_input / check_feedback first, which return HilError::DimensionMismatch"
            }
            RejectsArmOutOfRange => {
                "observe indexes its per-arm state with feedback.arm unchecked; call hil_core::policy::check_feedback first, which returns HilError::ArmOutOfRange"
            }
            RejectionHasNoEffect => {
                "the policy changes its state (counters, RNG, estimates) before validating its input, or panicked and is now unusable; validate first, then update"
            }
            Checkpoint => {
                "save() misses part of the state (the RNG, a counter) or restore() does not overwrite everything, or a poisoned object cannot save; serialise the whole learning state, RNG included, and restore all of it"
            }
            EnvironmentShape => {
                "the environment has no actions or a zero context dimension; build its ActionSpace and context_dim from its task"
            }
            EpisodeRuns => {
                "a call in the documented order (reset, next_item, observe, execute) failed; follow hil_core::environment::CallOrder"
            }
            EpisodeHasItems => {
                "reset produced an episode with no items; give every episode at least one item"
            }
            EpisodesEnd => "next_item never returns None; end the episode after its last item",
            CurrentItem => {
                "current_item() is not the item next_item() returned; store the item when next_item returns it"
            }
            ContextDimension => {
                "observe returns contexts of a dimension other than context_dim(); make them agree"
            }
            SuccessProbability => {
                "Outcome::success_probability is outside [0, 1] or not finite; report a probability or None"
            }
            BestActionInRange => {
                "best_action() names an arm outside the action space; index action_space()"
            }
            Replayable => {
                "the environment draws from randomness not reseeded by reset(seed) (thread_rng, time, state left over from the last episode); reseed every RNG in reset and clear per-episode state"
            }
            ExecuteRejectsArmOutOfRange => {
                "execute indexes per-arm tables unchecked, or consumes the observation before validating; call self.action_space().check(arm)? first"
            }
            OutOfOrderCalls => {
                "observe/execute were accepted (or panicked) out of order; track the order with hil_core::environment::CallOrder, which returns HilError::State"
            }
            Predicts => {
                "predict failed on a valid history; accept any WL_0 in [0, 1], any t and empty histories"
            }
            EmptyHistory => {
                "predict fails or is not finite for an empty history at t = 0; return WL_0 (or the model's baseline) there"
            }
            FinitePrediction => {
                "a prediction is NaN or infinite (a division by an elapsed time of 0, an exponential overflow); guard the arithmetic"
            }
            DeterministicPrediction => {
                "predict depends on hidden state or randomness; make it a pure function of its inputs"
            }
            Counterfactual => {
                "predict_if_queried is not predict on the history with the query appended; use the trait's default implementation or compute it the same way"
            }
            Answers => {
                "ask failed; a channel must answer every well-formed query (use Answer::Skip and friends for non-answers)"
            }
            ExpertArmInRange => {
                "the expert arm is not an index into query.actions (often a fixed task's list of actions assumed); map the answer into the query's own action space"
            }
            ResponseTime => {
                "response_time_s is negative or not finite; report seconds >= 0 or None"
            }
            AnswerConsistent => {
                "an Answer::Action's arm differs from expert_arm; build it with Response::action(arm)"
            }
            SeededReplay => {
                "the channel draws from randomness not reseeded by QueryChannel::seed; derive every draw from an RNG seeded there"
            }
            Destructor => {
                "the type's Drop implementation (or a field's) panicked when the object was dropped; a destructor cannot return an error, so release what it holds without unwrap/expect/indexing and ignore or log a failure there"
            }
        }
    }

    /// Whether [`Check::hint`] is already about a panic in the call the
    /// check makes (a refusal check, where panicking is the usual mistake);
    /// for the others a panic gets [`panic_hint`] instead.
    pub(crate) fn hint_covers_panics(self) -> bool {
        matches!(
            self,
            Check::RejectsWrongDimension
                | Check::RejectsArmOutOfRange
                | Check::ExecuteRejectsArmOutOfRange
                | Check::OutOfOrderCalls
                | Check::Destructor
        )
    }
}

/// The likely cause and fix of a failure caused by a panic in `method`
/// (as the panic guard names it).
pub(crate) fn panic_hint(method: &str) -> String {
    match method {
        "drop" => Check::Destructor.hint().to_string(),
        "restore" => "restore panicked (its message and location are in the detail); if it panicked while dropping the value it replaced (`*self = restored` runs the old value's Drop), fix that Drop; otherwise return HilError::State for a checkpoint restore cannot read, instead of unwrapping".to_string(),
        "factory" => "the factory panicked (its message and location are in the detail); return an error (HilError::InvalidParameter and friends) for parameters it cannot use".to_string(),
        "seed" | "best_action" | "current_item" | "name/n_arms/dim" | "name/action_space/context_dim" | "name" => format!(
            "`{method}` panicked (its message and location are in the detail); it cannot return an error, so the guard poisoned the object and every later call failed: make `{method}` unable to panic (no unwrap/expect/indexing that can fail)"
        ),
        _ => format!(
            "`{method}` panicked instead of returning an error (its message and location are in the detail); fix what the panic points at, and return a HilError for input the method cannot handle"
        ),
    }
}

impl std::fmt::Display for Check {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
