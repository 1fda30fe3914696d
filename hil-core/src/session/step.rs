//! The session driven one step at a time (ask/tell).
//!
//! An [`Episode`] holds everything an episode carries between two steps
//! (the workload tracker, the step events, where it stands at its item);
//! the [`Session`] methods below move it on:
//!
//! 1. [`Session::start_episode`] resets and seeds the components;
//! 2. [`Session::next_decision`] presents items and runs every attempt that
//!    needs no decision (the expert's arm repeated after a query) until the
//!    policy must decide, and returns that decision's input (ask), or `None`
//!    when no item is left;
//! 3. [`Session::feed_decision`] takes the decision (tell), asks the
//!    channel if it is a query, executes the arm and teaches the policy;
//! 4. [`Session::finish_episode`] scores the episode.
//!
//! [`Session::step`] is steps 2 and 3 with the session's own policy, and
//! [`Session::run_episode`] is a loop over it, so an outside loop (a
//! Gymnasium agent, a notebook) and `hil run` go through the same code.
//! The episode is kept apart from the session, which only borrows the
//! components, so that its owner can hold both between two calls.
//!
//! A call out of order (a second decision fed, a decision fed when none is
//! asked, an episode finished early) returns a [`HilError::State`] and
//! leaves the episode as it was. An error inside a step ends the episode:
//! every later call returns a state error, as `run_episode` would have
//! stopped there.

use std::sync::Arc;

use crate::action::ArmId;
use crate::context::Context;
use crate::context::Item;
use crate::decision::{Choice, Decision, Diagnostics};
use crate::error::{HilError, Result};
use crate::metrics::EpisodeMetrics;
use crate::policy::{DecisionInput, Feedback};
use crate::query::{Query, Response};
use crate::time::Timestep;
use crate::workload::{WorkloadForecast, WorkloadModel, WorkloadTracker};

use super::checks;
use super::event::{PendingStep, StepDecision, StepEvent};
use super::observer::SessionObserver;
use super::{ComponentSeeds, EpisodeReport, Session, SessionSettings};

/// Where an episode stands between two calls.
#[derive(Clone, Debug)]
enum Phase {
    /// The next item is to be presented (or the episode to end).
    BetweenItems,
    /// At `item`, before attempt `attempt`; after an answered query,
    /// `expert` is the arm every remaining attempt executes.
    AtItem {
        item: Item,
        attempt: u32,
        expert: Option<ArmId>,
    },
    /// The policy's decision at this attempt is awaited.
    Deciding {
        item: Item,
        attempt: u32,
        context: Context,
    },
    /// No item is left; the episode can be finished.
    Over,
    /// The report has been taken.
    Finished,
    /// A step failed; the episode cannot go on.
    Failed,
}

/// An episode in progress: what it carries from one step to the next.
/// Made by [`Session::start_episode`], moved on by the session's step
/// methods (see the [module documentation](self)).
pub struct Episode {
    seed: u64,
    /// The settings at the start (a session's may change between calls).
    settings: SessionSettings,
    /// The session's workload model, every prediction checked.
    workload: Arc<dyn WorkloadModel>,
    /// The model the policy forecasts with, every prediction checked.
    forecast: Arc<dyn WorkloadModel>,
    tracker: WorkloadTracker,
    events: Vec<StepEvent>,
    /// The last timestep taken (1-based; 0 before the first).
    t: Timestep,
    /// Items finished so far.
    items_seen: usize,
    phase: Phase,
}

impl std::fmt::Debug for Episode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Episode")
            .field("seed", &self.seed)
            .field("t", &self.t)
            .field("items_seen", &self.items_seen)
            .field("steps", &self.events.len())
            .field("phase", &self.phase)
            .finish()
    }
}

impl Episode {
    /// The seed that labels the episode.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Every step taken so far, in order.
    pub fn events(&self) -> &[StepEvent] {
        &self.events
    }

    /// The item being attempted, if any.
    pub fn item(&self) -> Option<&Item> {
        match &self.phase {
            Phase::AtItem { item, .. } | Phase::Deciding { item, .. } => Some(item),
            _ => None,
        }
    }

    /// The input of the decision awaited ([`Session::next_decision`]
    /// returned it), exactly as the session's policy would receive it; `None`
    /// when no decision is awaited.
    pub fn pending(&self) -> Option<DecisionInput<'_>> {
        let Phase::Deciding {
            item,
            attempt,
            context,
        } = &self.phase
        else {
            return None;
        };
        Some(DecisionInput {
            context,
            t: self.t,
            item_index: item.index,
            items_seen: self.items_seen,
            attempt: *attempt,
            workload: WorkloadForecast::new(
                Some(self.forecast.as_ref()),
                self.tracker.wl0(),
                self.tracker.history(),
                self.t,
            ),
        })
    }

    /// True once no item is left ([`Session::finish_episode`] may be called).
    pub fn is_over(&self) -> bool {
        matches!(self.phase, Phase::Over)
    }

    /// The state error for a call that `phase` does not allow.
    fn refuse(phase: &Phase, call: &str) -> HilError {
        let why = match phase {
            Phase::Deciding { .. } => "a decision is awaited: feed it with feed_decision first",
            Phase::BetweenItems | Phase::AtItem { .. } => {
                "no decision is awaited: call next_decision until it returns one (or None at the end)"
            }
            Phase::Over => "no item is left: call finish_episode",
            Phase::Finished => "the episode is finished: start a new one",
            Phase::Failed => "an earlier step failed, which ended the episode",
        };
        HilError::state("session", format!("{call}: {why}"))
    }
}

/// The parts of a step that precede its execution.
struct Decided {
    item: Item,
    attempt: u32,
    context: Context,
    decision: StepDecision,
    diagnostics: Option<Diagnostics>,
    response: Option<Response>,
    arm: ArmId,
    /// The expert's arm for the rest of the item, once a query was answered.
    expert: Option<ArmId>,
}

impl Session<'_> {
    /// Starts an episode seeded by `seed` (each component's seed derived
    /// from it, [`ComponentSeeds::derive`]): resets and seeds the
    /// components and tells `observers`. Move it on with
    /// [`Session::next_decision`] and [`Session::feed_decision`] (or
    /// [`Session::step`]) and end it with [`Session::finish_episode`].
    ///
    /// ```
    /// use std::sync::Arc;
    /// use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
    /// use hil_core::{ActionSpace, ArmId, Decision, Environment, PerfectExpert, Session, SessionSettings};
    ///
    /// let actions = ActionSpace::new(["left", "right"]).unwrap();
    /// let mut env = TableEnv::new(actions, vec![("apple", vec![0.9, 0.1])]).unwrap();
    /// let mut policy = ScriptedPolicy::new(2, env.context_dim(), vec![]);
    /// let mut expert = PerfectExpert::default();
    /// let mut session = Session::new(
    ///     SessionSettings::default().with_n_att(1),
    ///     &mut env,
    ///     &mut policy,
    ///     &mut expert,
    ///     Arc::new(CountingWorkload::new(0.1)),
    /// );
    /// let mut episode = session.start_episode(7, &mut []).unwrap();
    /// // An outside loop decides: here it always picks "left".
    /// while let Some(input) = session.next_decision(&mut episode, &mut []).unwrap() {
    ///     assert_eq!(input.attempt, 0);
    ///     session.feed_decision(&mut episode, Decision::act(ArmId(0)), &mut []).unwrap();
    /// }
    /// let report = session.finish_episode(&mut episode, &mut []).unwrap();
    /// assert_eq!((report.metrics.n_items, report.metrics.n_steps), (1, 1));
    /// ```
    pub fn start_episode(
        &mut self,
        seed: u64,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<Episode> {
        self.start_episode_with_seeds(seed, ComponentSeeds::derive(seed), observers)
    }

    /// Starts an episode with explicit per-component seeds; `seed` labels
    /// the episode in its report and for observers.
    pub fn start_episode_with_seeds(
        &mut self,
        seed: u64,
        seeds: ComponentSeeds,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<Episode> {
        self.settings.validate()?;
        self.check_shapes()?;
        self.environment.reset(seeds.environment)?;
        self.policy.seed(seeds.policy);
        self.channel.seed(seeds.channel);
        for o in observers.iter_mut() {
            o.on_episode_start(seed)?;
        }
        // Every prediction, for the trace, the policy and the score, is
        // checked to be a workload score.
        let workload: Arc<dyn WorkloadModel> =
            Arc::new(checks::CheckedWorkload(self.workload.clone()));
        let tracker = WorkloadTracker::new(workload.clone(), self.settings.wl0)?;
        let forecast: Arc<dyn WorkloadModel> = match &self.forecast {
            Some(f) => Arc::new(checks::CheckedWorkload(f.clone())),
            None => workload.clone(),
        };
        Ok(Episode {
            seed,
            settings: self.settings.clone(),
            workload,
            forecast,
            tracker,
            events: Vec::new(),
            t: 0,
            items_seen: 0,
            phase: Phase::BetweenItems,
        })
    }

    /// Moves `episode` on until the policy must decide (ask): presents the
    /// next item when one ends, and executes every attempt that needs no
    /// decision (after an answered query, the expert's arm until success or
    /// `n_att`). Returns the decision's input, or `None` when no item is
    /// left. A state error if a decision is already awaited.
    pub fn next_decision<'e>(
        &mut self,
        episode: &'e mut Episode,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<Option<DecisionInput<'e>>> {
        loop {
            match std::mem::replace(&mut episode.phase, Phase::Failed) {
                Phase::BetweenItems => {
                    let limit = episode.settings.max_items;
                    let next = if limit.is_none_or(|m| episode.items_seen < m) {
                        self.environment.next_item()?
                    } else {
                        None
                    };
                    let Some(item) = next else {
                        episode.phase = Phase::Over;
                        return Ok(None);
                    };
                    for o in observers.iter_mut() {
                        o.on_item_start(&item)?;
                    }
                    episode.phase = Phase::AtItem {
                        item,
                        attempt: 0,
                        expert: None,
                    };
                }
                Phase::AtItem {
                    item,
                    attempt,
                    expert,
                } => {
                    episode.t += 1;
                    let context = self.environment.observe()?;
                    context.check_dim(self.environment.context_dim())?;
                    match expert {
                        Some(arm) => {
                            let decided = Decided {
                                item,
                                attempt,
                                context,
                                decision: StepDecision::FollowExpert { arm },
                                diagnostics: None,
                                response: None,
                                arm,
                                expert,
                            };
                            self.execute(episode, decided, observers)?;
                        }
                        None => {
                            episode.phase = Phase::Deciding {
                                item,
                                attempt,
                                context,
                            };
                            return Ok(episode.pending());
                        }
                    }
                }
                Phase::Over => {
                    episode.phase = Phase::Over;
                    return Ok(None);
                }
                phase => {
                    let e = Episode::refuse(&phase, "next_decision");
                    episode.phase = phase;
                    return Err(e);
                }
            }
        }
    }

    /// Takes the decision awaited at `episode` (tell): asks the channel if
    /// it is a query, executes the arm, teaches the policy the outcome and
    /// tells `observers`. Returns the step. A state error if no decision
    /// is awaited ([`Session::next_decision`] returns one).
    pub fn feed_decision<'e>(
        &mut self,
        episode: &'e mut Episode,
        decision: Decision,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<&'e StepEvent> {
        let (item, attempt, context) = match std::mem::replace(&mut episode.phase, Phase::Failed) {
            Phase::Deciding {
                item,
                attempt,
                context,
            } => (item, attempt, context),
            phase => {
                let e = Episode::refuse(&phase, "feed_decision");
                episode.phase = phase;
                return Err(e);
            }
        };
        let decided = self.decided(episode, item, attempt, context, decision)?;
        self.execute(episode, decided, observers)?;
        episode
            .events
            .last()
            .ok_or_else(|| HilError::state("session", "a step left no event"))
    }

    /// One decision of the session's own policy: [`Session::next_decision`],
    /// the policy's `decide`, then [`Session::feed_decision`]. Returns false
    /// (having done nothing but the attempts that need no decision) when no
    /// item is left.
    pub fn step(
        &mut self,
        episode: &mut Episode,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<bool> {
        let decision = match self.next_decision(episode, observers)? {
            None => return Ok(false),
            Some(input) => self.policy.decide(&input),
        };
        let decision = decision.inspect_err(|_| episode.phase = Phase::Failed)?;
        self.feed_decision(episode, decision, observers)?;
        Ok(true)
    }

    /// Scores `episode` once no item is left and tells `observers`.
    /// A state error while items remain (call [`Session::next_decision`]
    /// until it returns `None`) or if the episode is already finished.
    pub fn finish_episode(
        &mut self,
        episode: &mut Episode,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<EpisodeReport> {
        if !episode.is_over() {
            return Err(Episode::refuse(&episode.phase, "finish_episode"));
        }
        episode.phase = Phase::Failed;
        let metrics = EpisodeMetrics::from_events(
            &episode.events,
            episode.settings.wl0,
            episode.workload.as_ref(),
        )?;
        for o in observers.iter_mut() {
            o.on_episode_end(&metrics)?;
        }
        episode.phase = Phase::Finished;
        Ok(EpisodeReport {
            seed: episode.seed,
            events: std::mem::take(&mut episode.events),
            metrics,
        })
    }

    /// The arm the policy's `decision` executes, after the query it may ask.
    fn decided(
        &mut self,
        episode: &mut Episode,
        item: Item,
        attempt: u32,
        context: Context,
        decision: Decision,
    ) -> Result<Decided> {
        checks::diagnostics(self.policy.name(), &decision.diagnostics)?;
        let t = episode.t;
        match decision.choice {
            Choice::Act { arm } => {
                // A policy's arm out of range keeps its kind (`ArmOutOfRange`).
                self.environment.action_space().check(arm)?;
                Ok(Decided {
                    item,
                    attempt,
                    context,
                    decision: StepDecision::Act { arm },
                    diagnostics: Some(decision.diagnostics),
                    response: None,
                    arm,
                    expert: None,
                })
            }
            Choice::Query { kind, fallback } => {
                self.environment.action_space().check(fallback)?;
                let query = Query {
                    t,
                    item: item.clone(),
                    kind,
                    actions: self.environment.action_space().clone(),
                    context: context.clone(),
                    oracle_best: self.environment.best_action(),
                };
                let response = self.channel.ask(&query)?;
                checks::response(self.channel.name(), &response)?;
                // The person was interrupted whatever they answered.
                episode.tracker.record(t, kind)?;
                let expert = response.expert_arm;
                if let Some(a) = expert {
                    self.check_arm(a, "expert answer")?;
                }
                Ok(Decided {
                    item,
                    attempt,
                    context,
                    decision: StepDecision::Query { kind, fallback },
                    diagnostics: Some(decision.diagnostics),
                    response: Some(response),
                    arm: expert.unwrap_or(fallback),
                    expert,
                })
            }
        }
    }

    /// Executes a decided step: the workload trace, the observers before
    /// the robot acts, the outcome, the policy's feedback, the event; then
    /// moves the episode to the item's next attempt or past the item.
    fn execute(
        &mut self,
        episode: &mut Episode,
        decided: Decided,
        observers: &mut [&mut dyn SessionObserver],
    ) -> Result<()> {
        let t = episode.t;
        let wl_t = episode.tracker.advance(t)?;
        let pending = PendingStep {
            t,
            item_index: decided.item.index,
            item_label: decided.item.label.clone(),
            attempt: decided.attempt,
            context: decided.context,
            decision: decided.decision,
            diagnostics: decided.diagnostics,
            response: decided.response,
            arm: decided.arm,
            wl_t,
        };
        for o in observers.iter_mut() {
            o.before_execute(&pending)?;
        }
        let outcome = self.environment.execute(decided.arm)?;
        if let Some(p) = outcome.success_probability
            && !(0.0..=1.0).contains(&p)
        {
            return Err(HilError::invalid_input(
                format!("success probability from `{}`", self.environment.name()),
                format!("{p} is outside [0, 1]"),
            ));
        }
        self.policy.observe(&Feedback {
            context: &pending.context,
            arm: decided.arm,
            reward: outcome.reward(),
            t,
            from_expert: decided.expert.is_some(),
        })?;
        let event = StepEvent {
            step: pending,
            outcome,
        };
        for o in observers.iter_mut() {
            o.on_step(&event)?;
        }
        let success = event.outcome.success;
        episode.events.push(event);
        let attempt = decided.attempt + 1;
        episode.phase = if success || attempt >= episode.settings.n_att {
            episode.items_seen += 1;
            Phase::BetweenItems
        } else {
            Phase::AtItem {
                item: decided.item,
                attempt,
                expert: decided.expert,
            }
        };
        Ok(())
    }
}
