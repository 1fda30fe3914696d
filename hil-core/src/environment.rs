//! The [`Environment`] trait: items to act on, contexts, and outcomes.

use serde::{Deserialize, Serialize};

use crate::action::{ActionSpace, ArmId};
use crate::context::Context;
use crate::decision::Outcome;
use crate::error::Result;

/// One item the robot must handle (a food piece on the plate).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Item {
    /// Position of the item in the episode (0-based).
    pub index: usize,
    /// The item's type (e.g. `banana`).
    pub label: String,
    /// Free-form description a human channel may show.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
}

/// A task the robot acts in: a seeded, replayable sequence of items, each
/// observed as a fresh context at every attempt.
///
/// Contract (checked by `hil_core::testing::check_environment`):
/// - after `reset(seed)` the same seed replays the same items, contexts and
///   outcomes for the same actions;
/// - `observe` returns contexts of dimension `context_dim()`;
/// - `execute` rejects arms outside `action_space()`;
/// - `best_action`, where provided, indexes the action space;
/// - `next_item` eventually returns `None` (episodes are finite).
///
/// Call order per episode: `reset`, then for every item `next_item`, then
/// one or more (`observe`, `execute`) pairs.
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
