//! Deliberately broken implementations: one defect per conformance
//! [`Check`], each a small real implementation that is correct except for
//! the one mistake plugin authors actually make (an unchecked index, an
//! unseeded RNG, a checkpoint that forgets the RNG).
//!
//! They exist to show that every check can fail: this crate's tests run each
//! one through its suite and assert that exactly the named check fails
//! ([`PolicyDefect::breaks`] and friends). With no defect each is a
//! conforming implementation, which passes every property.
//!
//! ```
//! use hil_conformance::broken::{PolicyDefect, policy};
//! use hil_conformance::{CheckOptions, check_policy_with};
//! let opts = CheckOptions::default();
//! let e = check_policy_with(&|| policy(Some(PolicyDefect::Unseeded), &opts), &opts).unwrap_err();
//! assert_eq!(e.check, PolicyDefect::Unseeded.breaks());
//! ```

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

use super::{Check, CheckOptions};
use hil_core::environment::CallOrder;
use hil_core::policy::{check_feedback, check_input};
use hil_core::{
    ActionSpace, ArmDiagnostics, ArmId, Context, Decision, DecisionInput, Diagnostics, Environment,
    Feedback, HilError, Item, Outcome, Policy, Query, QueryChannel, QueryKind, Response, Result,
    WorkloadInput, WorkloadModel,
};
use hil_plugin::{GuardedChannel, GuardedEnvironment, GuardedPolicy, GuardedWorkload};

/// A process-wide counter: state no seed reaches, like `thread_rng` or the
/// clock.
static UNSEEDED: AtomicU64 = AtomicU64::new(1);

fn unseeded() -> u64 {
    UNSEEDED.fetch_add(1, Ordering::Relaxed)
}

/// Where the guarded wrappers say a panicking object came from.
fn in_process() -> PathBuf {
    PathBuf::from("<in-process test object>")
}

macro_rules! defects {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $variant:ident => $check:ident),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vmeta])* $variant),*
        }

        impl $name {
            /// Every defect.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];

            /// The check this defect fails.
            pub fn breaks(self) -> Check {
                match self {
                    $($name::$variant => Check::$check),*
                }
            }
        }
    };
}

defects! {
    /// How [`policy`] is broken.
    PolicyDefect {
        /// The factory refuses to build.
        FactoryFails => Build,
        /// Sizes itself with one arm more than the build context offers.
        IgnoresBuildContext => PolicyShape,
        /// `decide` fails on valid input after a few steps.
        DecideFails => PolicyDecides,
        /// Returns arm `n_arms` at the fifth step (an off-by-one).
        ArmOutOfRange => ArmInRange,
        /// Reports 0/0 as the estimate of an arm never tried.
        NanDiagnostics => FiniteDiagnostics,
        /// Reports diagnostics for all arms but the last.
        ShortDiagnostics => DiagnosticsCoverArms,
        /// Explores with randomness no seed reaches.
        Unseeded => Determinism,
        /// Indexes its weights with the context unchecked: a longer context
        /// panics (run under the plugin panic guard, as a plugin would be),
        /// a shorter one is accepted.
        PanicsOnLongerContext => RejectsWrongDimension,
        /// Refuses a wrong dimension with `InvalidInput` instead of
        /// `DimensionMismatch`.
        WrongDimensionErrorKind => RejectsWrongDimension,
        /// Folds an out-of-range arm into range (`arm % n_arms`).
        AcceptsArmOutOfRange => RejectsArmOutOfRange,
        /// Counts the feedback before validating it.
        UpdatesBeforeValidating => RejectionHasNoEffect,
        /// Saves everything but its RNG position.
        CheckpointForgetsRng => Checkpoint,
        /// Panics in `save` (under the panic guard): a failure, not a skip.
        PanicsInSave => Checkpoint,
        /// `restore` leaves its step counter as it was: the state saved
        /// after restoring differs at the key `steps`.
        RestoreSkipsSteps => Checkpoint,
        /// `decide` fails on its 50th call (a buffer that fills up): only a
        /// long trajectory finds it.
        FailsOnCall50 => PolicyDecides,
        /// Its destructor panics (under the panic guard, as a plugin's).
        PanicsInDrop => Destructor,
        /// Panics in `seed` (under the panic guard), which poisons it.
        PanicsInSeed => PolicyDecides,
        /// A value `restore` replaces panics in its destructor, inside
        /// `restore` (under the panic guard).
        DropPanicsInRestore => Checkpoint,
    }
}

defects! {
    /// How [`environment`] is broken.
    EnvironmentDefect {
        /// Declares a context dimension of 0.
        ZeroContextDim => EnvironmentShape,
        /// `reset` fails.
        ResetFails => EpisodeRuns,
        /// Episodes have no items.
        EmptyEpisode => EpisodeHasItems,
        /// `next_item` never returns `None`.
        Endless => EpisodesEnd,
        /// `current_item` always returns `None`.
        ForgetsCurrentItem => CurrentItem,
        /// Observes contexts one longer than declared.
        LongerContexts => ContextDimension,
        /// Reports success probabilities above 1.
        ProbabilityAboveOne => SuccessProbability,
        /// Names arm `n` as the best action.
        BestActionOutOfRange => BestActionInRange,
        /// Adds noise no seed reaches.
        Unseeded => Replayable,
        /// Folds an out-of-range arm into range.
        AcceptsArmOutOfRange => ExecuteRejectsArmOutOfRange,
        /// Consumes the observation before validating the arm.
        ConsumesBeforeValidating => ExecuteRejectsArmOutOfRange,
        /// Keeps no call order: observes item 0 before `next_item`.
        IgnoresCallOrder => OutOfOrderCalls,
        /// `execute` fails on its 50th call in the instance's life.
        FailsOnCall50 => EpisodeRuns,
        /// Its destructor panics.
        PanicsInDrop => Destructor,
    }
}

defects! {
    /// How [`workload_model`] is broken.
    WorkloadDefect {
        /// `predict` fails for histories of more than five queries.
        PredictFails => Predicts,
        /// Returns NaN for an empty history.
        NanOnEmptyHistory => EmptyHistory,
        /// Overflows to infinity for histories of more than 20 queries.
        InfiniteOnLongHistories => FinitePrediction,
        /// Drifts with a call counter.
        Stateful => DeterministicPrediction,
        /// `predict_if_queried` adds its own increment.
        WrongCounterfactual => Counterfactual,
        /// Keeps the last 50 queries in a fixed buffer and fails once a
        /// history holds more: only a long history finds it.
        FailsAfter50Queries => Predicts,
        /// Its destructor panics.
        PanicsInDrop => Destructor,
    }
}

defects! {
    /// How [`query_channel`] is broken.
    ChannelDefect {
        /// `ask` fails.
        AskFails => Answers,
        /// Answers with an index into six actions whatever the query offers.
        AssumesSixActions => ExpertArmInRange,
        /// Reports negative response times.
        NegativeResponseTime => ResponseTime,
        /// `expert_arm` differs from the answered arm.
        InconsistentAnswer => AnswerConsistent,
        /// Answers with randomness no seed reaches.
        Unseeded => SeededReplay,
        /// `ask` fails on its 50th call.
        FailsOnCall50 => Answers,
        /// Its destructor panics.
        PanicsInDrop => Destructor,
    }
}

// ---------------------------------------------------------------- policy

/// A policy built for `opts` (an epsilon-greedy learner over success
/// rates, which asks at the first attempt of the first two items), broken
/// by `defect`. Defects that panic run under [`GuardedPolicy`], as a
/// plugin's objects do.
pub fn policy(defect: Option<PolicyDefect>, opts: &CheckOptions) -> Result<Box<dyn Policy>> {
    use PolicyDefect as D;
    if defect == Some(D::FactoryFails) {
        return Err(HilError::invalid_parameter(
            "epsilon",
            -1,
            "must be in [0, 1]",
        ));
    }
    let extra = usize::from(defect == Some(D::IgnoresBuildContext));
    let p = EpsilonGreedy {
        defect,
        n_arms: opts.actions().len() + extra,
        dim: opts.context_dim(),
        counts: vec![(0.0, 0.0); opts.actions().len() + extra],
        weights: vec![0.1; opts.context_dim()],
        seed: 0,
        rng: ChaCha8Rng::seed_from_u64(0),
        steps: 0,
    };
    if matches!(
        defect,
        Some(
            D::PanicsOnLongerContext
                | D::PanicsInSave
                | D::PanicsInDrop
                | D::PanicsInSeed
                | D::DropPanicsInRestore
        )
    ) {
        Ok(Box::new(GuardedPolicy::new(
            Box::new(p),
            in_process(),
            "broken_policy",
        )?))
    } else {
        Ok(Box::new(p))
    }
}

#[derive(Debug)]
struct EpsilonGreedy {
    defect: Option<PolicyDefect>,
    n_arms: usize,
    dim: usize,
    /// Per arm: (successes, attempts).
    counts: Vec<(f64, f64)>,
    weights: Vec<f64>,
    seed: u64,
    rng: ChaCha8Rng,
    steps: u64,
}

/// The one place this module builds [`Diagnostics`].
fn diagnostics(rates: impl Iterator<Item = f64>) -> Diagnostics {
    Diagnostics::new().with_arms(
        rates
            .map(|r| ArmDiagnostics::new(r, 0.1, r + 0.1))
            .collect(),
    )
}

impl EpsilonGreedy {
    fn is(&self, d: PolicyDefect) -> bool {
        self.defect == Some(d)
    }
}

impl Policy for EpsilonGreedy {
    fn name(&self) -> &str {
        "broken_policy"
    }
    fn n_arms(&self) -> usize {
        self.n_arms
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn seed(&mut self, seed: u64) {
        assert!(
            !self.is(PolicyDefect::PanicsInSeed),
            "the seed does not fit the generator"
        );
        self.seed = seed;
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }

    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        use PolicyDefect as D;
        match self.defect {
            Some(D::PanicsOnLongerContext) => {
                let mut score = 0.0;
                for (i, v) in input.context.iter().enumerate() {
                    score += self.weights[i] * v;
                }
                let _ = score;
            }
            Some(D::WrongDimensionErrorKind) if input.context.dim() != self.dim => {
                return Err(HilError::invalid_input("context", "wrong length"));
            }
            _ => check_input(self, input)?,
        }
        self.steps += 1;
        if self.is(D::DecideFails) && self.steps > 3 {
            return Err(HilError::state("broken_policy", "ran out of patience"));
        }
        if self.is(D::FailsOnCall50) && self.steps == 50 {
            return Err(HilError::state("broken_policy", "the step buffer is full"));
        }
        let rate = |(s, n): (f64, f64)| s / n;
        let rates: Vec<f64> = self
            .counts
            .iter()
            .map(|&c| {
                if c.1 > 0.0 || self.is(D::NanDiagnostics) {
                    rate(c)
                } else {
                    0.5
                }
            })
            .collect();
        let explore = if self.is(D::Unseeded) {
            unseeded() % 3 == 0
        } else {
            self.rng.random_bool(0.3)
        };
        let mut arm = if explore {
            self.rng.random_range(0..self.n_arms)
        } else {
            (0..self.n_arms)
                .max_by(|&a, &b| rates[a].total_cmp(&rates[b]).then(b.cmp(&a)))
                .unwrap_or(0)
        };
        if self.is(D::ArmOutOfRange) && self.steps == 5 {
            arm = self.n_arms;
        }
        let shown = self.n_arms - usize::from(self.is(D::ShortDiagnostics));
        let mut d = if input.item_index < 2 && input.attempt == 0 {
            Decision::query(QueryKind::default(), ArmId(arm))
        } else {
            Decision::act(ArmId(arm))
        };
        d.diagnostics = diagnostics(rates.into_iter().take(shown));
        Ok(d)
    }

    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        use PolicyDefect as D;
        let mut arm = feedback.arm.0;
        if self.is(D::UpdatesBeforeValidating) {
            let c = &mut self.counts[arm.min(self.n_arms - 1)];
            c.0 += feedback.reward;
            c.1 += 1.0;
            check_feedback(self, feedback)?;
            return Ok(());
        }
        if self.is(D::AcceptsArmOutOfRange) {
            feedback.context.check_dim(self.dim)?;
            arm %= self.n_arms;
        } else if self.is(D::WrongDimensionErrorKind) && feedback.context.dim() != self.dim {
            return Err(HilError::invalid_input("context", "wrong length"));
        } else {
            check_feedback(self, feedback)?;
        }
        let c = &mut self.counts[arm];
        c.0 += feedback.reward;
        c.1 += 1.0;
        Ok(())
    }

    fn save(&self) -> Result<Value> {
        assert!(
            !self.is(PolicyDefect::PanicsInSave),
            "the state is not serialisable yet"
        );
        let word_pos = if self.is(PolicyDefect::CheckpointForgetsRng) {
            0
        } else {
            self.rng.get_word_pos()
        };
        Ok(json!({
            "counts": self.counts,
            "seed": self.seed,
            "word_pos": word_pos.to_string(),
            "steps": self.steps,
        }))
    }

    fn restore(&mut self, state: Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        struct S {
            counts: Vec<(f64, f64)>,
            seed: u64,
            word_pos: String,
            steps: u64,
        }
        // What restore replaces; for the defect, its destructor panics.
        let _replaced = Replaced(self.is(PolicyDefect::DropPanicsInRestore));
        let s: S =
            serde_json::from_value(state).map_err(|e| HilError::serde("broken_policy state", e))?;
        if s.counts.len() != self.n_arms {
            return Err(HilError::state(
                "broken_policy",
                "the checkpoint is for another number of arms",
            ));
        }
        let pos: u128 = s
            .word_pos
            .parse()
            .map_err(|e| HilError::serde("broken_policy word_pos", e))?;
        self.counts = s.counts;
        self.seed(s.seed);
        self.rng.set_word_pos(pos);
        if !self.is(PolicyDefect::RestoreSkipsSteps) {
            self.steps = s.steps;
        }
        Ok(())
    }
}

/// The destructor of every broken type: panics for the defect
/// `PanicsInDrop`.
fn drop_panics(panics: bool) {
    // Not while unwinding already: that would abort the test process.
    if panics && !std::thread::panicking() {
        panic!("the destructor could not release its resources");
    }
}

/// Part of a policy's state that `restore` replaces (and so drops).
struct Replaced(bool);

impl Drop for Replaced {
    fn drop(&mut self) {
        drop_panics(self.0);
    }
}

impl Drop for EpsilonGreedy {
    fn drop(&mut self) {
        drop_panics(self.is(PolicyDefect::PanicsInDrop));
    }
}

// ----------------------------------------------------------- environment

/// Success probabilities of the three actions for each item type.
const TABLE: [(&str, [f64; 3]); 3] = [
    ("grape", [0.2, 0.8, 0.5]),
    ("banana", [0.7, 0.3, 0.4]),
    ("carrot", [0.1, 0.4, 0.9]),
];

/// An environment of four items with fixed success probabilities per
/// action and a 3-d context (the item type and two seeded noise features),
/// broken by `defect`.
pub fn environment(defect: Option<EnvironmentDefect>) -> Result<Box<dyn Environment>> {
    let env = TableEnv {
        defect,
        actions: ActionSpace::new(["skewer", "tilt", "scoop"])?,
        rng: ChaCha8Rng::seed_from_u64(0),
        next: 0,
        current: None,
        order: CallOrder::new("broken_environment"),
        executed: 0,
    };
    Ok(Box::new(GuardedEnvironment::new(
        Box::new(env),
        in_process(),
        "broken_environment",
    )?))
}

#[derive(Debug)]
struct TableEnv {
    defect: Option<EnvironmentDefect>,
    actions: ActionSpace,
    rng: ChaCha8Rng,
    next: usize,
    current: Option<Item>,
    order: CallOrder,
    /// Calls of `execute` in the instance's life (not reset by `reset`).
    executed: u64,
}

impl Drop for TableEnv {
    fn drop(&mut self) {
        drop_panics(self.is(EnvironmentDefect::PanicsInDrop));
    }
}

impl TableEnv {
    fn is(&self, d: EnvironmentDefect) -> bool {
        self.defect == Some(d)
    }
    fn probs(&self) -> [f64; 3] {
        let i = self.current.as_ref().map_or(0, |c| c.index);
        TABLE[i % TABLE.len()].1
    }
}

impl Environment for TableEnv {
    fn name(&self) -> &str {
        "broken_environment"
    }
    fn action_space(&self) -> &ActionSpace {
        &self.actions
    }
    fn context_dim(&self) -> usize {
        if self.is(EnvironmentDefect::ZeroContextDim) {
            0
        } else {
            3
        }
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        if self.is(EnvironmentDefect::ResetFails) {
            return Err(HilError::backend(
                "broken_environment",
                "the simulator did not start",
            ));
        }
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.next = 0;
        self.current = None;
        self.order.on_reset();
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        let end = if self.is(EnvironmentDefect::EmptyEpisode) {
            0
        } else if self.is(EnvironmentDefect::Endless) {
            usize::MAX
        } else {
            4
        };
        self.current = (self.next < end)
            .then(|| Item::new(self.next, TABLE[self.next % TABLE.len()].0.to_string()));
        self.next += 1;
        self.order.on_next_item(self.current.is_some());
        Ok(self.current.clone())
    }
    fn observe(&mut self) -> Result<Context> {
        if !self.is(EnvironmentDefect::IgnoresCallOrder) {
            self.order.on_observe()?;
        }
        let i = self.current.as_ref().map_or(0, |c| c.index);
        let noise = if self.is(EnvironmentDefect::Unseeded) {
            unseeded() as f64 * 1e-3
        } else {
            self.rng.random_range(-1.0..1.0)
        };
        let mut x = vec![
            (i % TABLE.len()) as f64,
            noise,
            self.rng.random_range(-1.0..1.0),
        ];
        if self.is(EnvironmentDefect::LongerContexts) {
            x.push(0.0);
        }
        Context::new(x)
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        use EnvironmentDefect as D;
        self.executed += 1;
        if self.is(D::FailsOnCall50) && self.executed == 50 {
            return Err(HilError::backend(
                "broken_environment",
                "the simulator's log is full",
            ));
        }
        let mut arm = arm.0;
        match self.defect {
            Some(D::AcceptsArmOutOfRange) => {
                self.order.on_execute()?;
                arm %= self.actions.len();
            }
            Some(D::ConsumesBeforeValidating) => {
                self.order.on_execute()?;
                self.actions.check(ArmId(arm))?;
            }
            Some(D::IgnoresCallOrder) => self.actions.check(ArmId(arm))?,
            _ => {
                self.actions.check(ArmId(arm))?;
                self.order.on_execute()?;
            }
        }
        let p = self.probs()[arm];
        let reported = if self.is(D::ProbabilityAboveOne) {
            p + 1.0
        } else {
            p
        };
        Ok(Outcome::new(self.rng.random_bool(p)).with_success_probability(reported))
    }
    fn best_action(&self) -> Option<ArmId> {
        if self.is(EnvironmentDefect::BestActionOutOfRange) {
            return Some(ArmId(self.actions.len()));
        }
        let p = self.probs();
        (0..3).max_by(|&a, &b| p[a].total_cmp(&p[b])).map(ArmId)
    }
    fn current_item(&self) -> Option<&Item> {
        if self.is(EnvironmentDefect::ForgetsCurrentItem) {
            None
        } else {
            self.current.as_ref()
        }
    }
}

// -------------------------------------------------------- workload model

/// WL_t = clamp(WL_0 + 0.1 · queries up to t, 0, 1), broken by `defect`.
pub fn workload_model(defect: Option<WorkloadDefect>) -> Result<Box<dyn WorkloadModel>> {
    let m = Counting {
        defect,
        calls: AtomicU64::new(0),
    };
    Ok(Box::new(GuardedWorkload::new(
        Box::new(m),
        in_process(),
        "broken_workload",
    )?))
}

#[derive(Debug)]
struct Counting {
    defect: Option<WorkloadDefect>,
    calls: AtomicU64,
}

impl Drop for Counting {
    fn drop(&mut self) {
        drop_panics(self.defect == Some(WorkloadDefect::PanicsInDrop));
    }
}

impl WorkloadModel for Counting {
    fn name(&self) -> &str {
        "broken_workload"
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        use WorkloadDefect as D;
        let n = input.history.count_until(input.t);
        let mut wl = (input.wl0 + 0.1 * n as f64).clamp(0.0, 1.0);
        match self.defect {
            Some(D::PredictFails) if n > 5 => {
                return Err(HilError::invalid_input("history", "too long"));
            }
            Some(D::FailsAfter50Queries) if input.history.len() > 50 => {
                return Err(HilError::invalid_input(
                    "history",
                    "more queries than the buffer of 50",
                ));
            }
            Some(D::NanOnEmptyHistory) if n == 0 => wl = f64::NAN,
            Some(D::InfiniteOnLongHistories) if n > 20 => wl = f64::INFINITY,
            Some(D::Stateful) => {
                wl += 1e-9 * self.calls.fetch_add(1, Ordering::Relaxed) as f64;
            }
            _ => {}
        }
        Ok(wl)
    }
    fn predict_if_queried(&self, input: &WorkloadInput<'_>, kind: QueryKind) -> Result<f64> {
        let mut h = input.history.clone();
        h.push(input.t, kind)?;
        let wl = self.predict(&input.with_history(&h))?;
        Ok(
            if self.defect == Some(WorkloadDefect::WrongCounterfactual) {
                wl + 0.05
            } else {
                wl
            },
        )
    }
}

// --------------------------------------------------------- query channel

/// A simulated expert answering the oracle's best action with probability
/// 0.8 (else a random action of the query) after 1 to 5 seconds, broken by
/// `defect`.
pub fn query_channel(defect: Option<ChannelDefect>) -> Result<Box<dyn QueryChannel>> {
    let ch = NoisyExpert {
        defect,
        rng: ChaCha8Rng::seed_from_u64(0),
        asked: 0,
    };
    Ok(Box::new(GuardedChannel::new(
        Box::new(ch),
        in_process(),
        "broken_channel",
    )?))
}

#[derive(Debug)]
struct NoisyExpert {
    defect: Option<ChannelDefect>,
    rng: ChaCha8Rng,
    /// Calls of `ask` in the instance's life.
    asked: u64,
}

impl Drop for NoisyExpert {
    fn drop(&mut self) {
        drop_panics(self.defect == Some(ChannelDefect::PanicsInDrop));
    }
}

impl QueryChannel for NoisyExpert {
    fn name(&self) -> &str {
        "broken_channel"
    }
    fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }
    fn ask(&mut self, query: &Query) -> Result<Response> {
        use ChannelDefect as D;
        self.asked += 1;
        if self.defect == Some(D::AskFails)
            || (self.defect == Some(D::FailsOnCall50) && self.asked == 50)
        {
            return Err(HilError::channel("broken_channel", "the person left"));
        }
        let n = if self.defect == Some(D::AssumesSixActions) {
            6
        } else {
            query.actions.len()
        };
        let correct = if self.defect == Some(D::Unseeded) {
            unseeded() % 7 < 5
        } else {
            self.rng.random_bool(0.8)
        };
        let arm = match query.oracle_best {
            Some(best) if correct => best.0,
            _ => self.rng.random_range(0..n),
        };
        let mut r = Response::action(ArmId(arm));
        if self.defect == Some(D::InconsistentAnswer) {
            r.expert_arm = Some(ArmId((arm + 1) % n));
        }
        let seconds = self.rng.random_range(1.0..5.0);
        r.response_time_s = Some(if self.defect == Some(D::NegativeResponseTime) {
            -seconds
        } else {
            seconds
        });
        Ok(r)
    }
}
