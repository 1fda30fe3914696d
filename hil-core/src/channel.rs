//! The [`QueryChannel`] trait: how a query reaches a person and comes back.

use crate::error::Result;
use crate::query::{Query, Response};

/// Poses queries to an expert (a person, or a simulated one) and returns the
/// answer.
///
/// Contract (checked by `hil_core::testing::check_query_channel`): a
/// response's `expert_arm`, when present, indexes the query's action space;
/// response times are finite and non-negative.
///
/// A channel that cannot reach the person at all returns an error; a person
/// who declines or does not answer in time is a normal [`Response`]
/// ([`crate::Answer::Declined`], [`crate::Answer::TimedOut`]).
pub trait QueryChannel: Send {
    /// Short name for logs.
    fn name(&self) -> &str;

    /// Reseeds the channel's own randomness (simulated experts).
    fn seed(&mut self, seed: u64) {
        let _ = seed;
    }

    /// Where a person answers, for channels that serve one (e.g. the URL of
    /// a web page), so that a front end can show it. None by default.
    fn endpoint(&self) -> Option<String> {
        None
    }

    /// Asks the query and waits for the answer.
    fn ask(&mut self, query: &Query) -> Result<Response>;
}
