//! Extension hooks into the session loop, all no-ops by default.

use crate::context::Item;
use crate::error::Result;
use crate::event::{PendingStep, StepEvent};
use crate::metrics::EpisodeMetrics;

/// Receives the session's events as they happen. Every hook has a no-op
/// default, so an observer implements only what it needs. An error from a
/// hook stops the session (a log that cannot be written must not let the
/// robot act).
pub trait SessionObserver {
    /// An episode starts with this seed.
    fn on_episode_start(&mut self, seed: u64) -> Result<()> {
        let _ = seed;
        Ok(())
    }

    /// A new item is presented.
    fn on_item_start(&mut self, item: &Item) -> Result<()> {
        let _ = item;
        Ok(())
    }

    /// A step is decided; the robot acts right after this returns.
    fn before_execute(&mut self, step: &PendingStep) -> Result<()> {
        let _ = step;
        Ok(())
    }

    /// A step is complete.
    fn on_step(&mut self, event: &StepEvent) -> Result<()> {
        let _ = event;
        Ok(())
    }

    /// The episode ended.
    fn on_episode_end(&mut self, metrics: &EpisodeMetrics) -> Result<()> {
        let _ = metrics;
        Ok(())
    }
}

/// Collects every step event in memory.
#[derive(Debug, Default)]
pub struct EventCollector {
    /// The events, in order.
    pub events: Vec<StepEvent>,
}

impl SessionObserver for EventCollector {
    fn on_step(&mut self, event: &StepEvent) -> Result<()> {
        self.events.push(event.clone());
        Ok(())
    }
}
