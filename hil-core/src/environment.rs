//! The [`Environment`] trait: items to act on, contexts, and outcomes.
//! (An [`Item`] and its [`Context`] are vocabulary of their own, in
//! [`crate::context`], since queries describe them too.)

use crate::action::{ActionSpace, ArmId};
use crate::context::{Context, Item};
use crate::decision::Outcome;
use crate::error::{HilError, Result};

/// A task the robot acts in: a seeded, replayable sequence of items, each
/// observed as a fresh context at every attempt.
///
/// Contract (checked by `hil_conformance::check_environment`):
/// - after `reset(seed)` the same seed replays the same items, contexts and
///   outcomes for the same actions;
/// - `observe` returns contexts of dimension `context_dim()`;
/// - `execute` rejects arms outside `action_space()`;
/// - `best_action`, where provided, indexes the action space;
/// - `next_item` eventually returns `None` (episodes are finite).
///
/// Call order per episode: `reset`, then for every item `next_item`, then
/// one or more (`observe`, `execute`) pairs; [`CallOrder`] enforces it.
pub trait Environment: Send {
    /// Short name for logs.
    fn name(&self) -> &str;

    /// The robot actions available.
    fn action_space(&self) -> &ActionSpace;

    /// Dimension of the contexts this environment produces.
    fn context_dim(&self) -> usize;

    /// Starts a new episode seeded by `seed`.
    fn reset(&mut self, seed: u64) -> Result<()>;

    /// Advances to the next item, or returns `None` at the end of the episode.
    fn next_item(&mut self) -> Result<Option<Item>>;

    /// Observes a fresh context of the current item (a new image, a new pose).
    fn observe(&mut self) -> Result<Context>;

    /// Executes `arm` on the current observation and reports the outcome.
    fn execute(&mut self, arm: ArmId) -> Result<Outcome>;

    /// The best action for the current observation, if the environment knows
    /// it (simulation). Simulated experts answer with it.
    fn best_action(&self) -> Option<ArmId> {
        None
    }

    /// The current item, if any.
    fn current_item(&self) -> Option<&Item>;
}

/// Where an environment is in its per-episode call order, so that every
/// environment refuses out-of-order calls the same way (with a
/// [`HilError::State`] naming the environment and the call it expected)
/// instead of each one keeping its own flags.
///
/// The order is the one [`Environment`] documents: `reset`, then for every
/// item `next_item`, then one or more (`observe`, `execute`) pairs. Each
/// `execute` consumes the observation it acts on, so the next attempt needs
/// a fresh `observe`. A new instance is ready for `next_item`, like one just
/// reset (environments seed themselves on construction).
///
/// ```
/// use hil_core::HilError;
/// use hil_core::environment::CallOrder;
///
/// let mut order = CallOrder::new("my_env");
/// assert!(matches!(order.on_observe(), Err(HilError::State { .. })));
/// order.on_reset();
/// order.on_next_item(true);
/// order.on_observe()?;
/// order.on_execute()?;
/// // The observation was used up: another attempt observes again.
/// assert!(matches!(order.on_execute(), Err(HilError::State { .. })));
/// order.on_next_item(false); // the episode is over
/// assert!(!order.has_item());
/// # Ok::<(), HilError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CallOrder {
    env: String,
    state: CallState,
}

/// The states of [`CallOrder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CallState {
    /// After construction or `reset`: no item yet.
    NoItem,
    /// `next_item` returned an item; it has not been observed since the last
    /// `execute`.
    Item,
    /// The current item was observed; `execute` may act on it.
    Observed,
    /// `next_item` returned `None`: the episode is over.
    Ended,
}

impl CallOrder {
    /// The call order of the environment named `env` (used in errors).
    pub fn new(env: impl Into<String>) -> Self {
        Self {
            env: env.into(),
            state: CallState::NoItem,
        }
    }

    /// `reset` was called: the episode starts over with no item.
    pub fn on_reset(&mut self) {
        self.state = CallState::NoItem;
    }

    /// `next_item` was called and found an item (`has_item`) or the end of
    /// the episode. Always allowed: the session may move on after any attempt.
    pub fn on_next_item(&mut self, has_item: bool) {
        self.state = if has_item {
            CallState::Item
        } else {
            CallState::Ended
        };
    }

    /// `observe` is being called: an error unless there is a current item.
    /// Observing again before executing is allowed (a fresh look).
    pub fn on_observe(&mut self) -> Result<()> {
        match self.state {
            CallState::Item | CallState::Observed => {
                self.state = CallState::Observed;
                Ok(())
            }
            CallState::NoItem => Err(self.error("observe", "next_item")),
            CallState::Ended => Err(self.ended("observe")),
        }
    }

    /// `execute` is being called: an error unless the current item was
    /// observed since the last `execute`. Consumes that observation.
    pub fn on_execute(&mut self) -> Result<()> {
        match self.state {
            CallState::Observed => {
                self.state = CallState::Item;
                Ok(())
            }
            CallState::Item => Err(self.error("execute", "observe")),
            CallState::NoItem => Err(self.error("execute", "next_item and observe")),
            CallState::Ended => Err(self.ended("execute")),
        }
    }

    /// Whether `next_item` last returned an item.
    pub fn has_item(&self) -> bool {
        matches!(self.state, CallState::Item | CallState::Observed)
    }

    /// Whether the current item is observed and not yet acted on.
    pub fn is_observed(&self) -> bool {
        self.state == CallState::Observed
    }

    fn error(&self, call: &str, expected: &str) -> HilError {
        HilError::state(
            self.env.clone(),
            format!("`{call}` called out of order: call {expected} first"),
        )
    }

    fn ended(&self, call: &str) -> HilError {
        HilError::state(
            self.env.clone(),
            format!("`{call}` called after the episode ended: call reset first"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn is_state(r: Result<()>) -> bool {
        matches!(r, Err(HilError::State { component, .. }) if component == "e")
    }

    #[test]
    fn a_new_order_needs_an_item_before_observe_or_execute() {
        let mut o = CallOrder::new("e");
        assert!(!o.has_item());
        assert!(is_state(o.on_observe()));
        assert!(is_state(o.on_execute()));
        o.on_reset();
        assert!(is_state(o.on_observe()));
        assert!(is_state(o.on_execute()));
    }

    #[test]
    fn the_documented_order_is_accepted() {
        let mut o = CallOrder::new("e");
        o.on_reset();
        o.on_next_item(true);
        assert!(o.has_item() && !o.is_observed());
        o.on_observe().unwrap();
        assert!(o.is_observed());
        o.on_execute().unwrap();
        assert!(o.has_item() && !o.is_observed());
        // A second attempt at the same item, observing twice first.
        o.on_observe().unwrap();
        o.on_observe().unwrap();
        o.on_execute().unwrap();
        o.on_next_item(true);
        o.on_observe().unwrap();
        o.on_execute().unwrap();
    }

    #[test]
    fn execute_needs_a_fresh_observation() {
        let mut o = CallOrder::new("e");
        o.on_next_item(true);
        assert!(is_state(o.on_execute()));
        o.on_observe().unwrap();
        o.on_execute().unwrap();
        assert!(is_state(o.on_execute()));
    }

    #[test]
    fn next_item_drops_an_unused_observation() {
        let mut o = CallOrder::new("e");
        o.on_next_item(true);
        o.on_observe().unwrap();
        o.on_next_item(true);
        assert!(is_state(o.on_execute()));
    }

    #[test]
    fn nothing_but_next_item_or_reset_follows_the_end() {
        let mut o = CallOrder::new("e");
        o.on_next_item(true);
        o.on_observe().unwrap();
        o.on_next_item(false);
        assert!(!o.has_item());
        assert!(is_state(o.on_observe()));
        assert!(is_state(o.on_execute()));
        o.on_next_item(false);
        assert!(!o.has_item());
        o.on_reset();
        o.on_next_item(true);
        o.on_observe().unwrap();
    }

    #[test]
    fn reset_drops_the_current_item() {
        let mut o = CallOrder::new("e");
        o.on_next_item(true);
        o.on_observe().unwrap();
        o.on_reset();
        assert!(!o.has_item());
        assert!(is_state(o.on_execute()));
    }
}
