//! The [`QueryChannel`] trait: how a query reaches a person and comes back.

use crate::error::{HilError, Result};
use crate::query::{Query, Response};

/// Poses queries to an expert (a person, or a simulated one) and returns the
/// answer.
///
/// Contract (checked by `hil_conformance::check_query_channel`): a
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

/// The perfect expert of the paper's simulations: answers every query with
/// the environment's best action ([`Query::oracle_best`]), instantly and
/// whatever the response type (in the paper the response type changes only
/// the workload a query costs, not what the answer tells the robot).
///
/// This is the one perfect-expert channel: the simulated experts of
/// `hil-channels` ask it for the truth before they add errors, declines and
/// response times. It is an error ([`HilError::Channel`]) to ask it where
/// the environment does not know its best action.
///
/// ```
/// use hil_core::channel::PerfectExpert;
/// use hil_core::{ActionSpace, ArmId, Context, HilError, Item, Query, QueryChannel};
///
/// let mut expert = PerfectExpert::default();
/// let actions = ActionSpace::new(["left", "right"])?;
/// let mut query = Query::new(1, Item::new(0, "cup"), Default::default(), actions, Context::new(vec![1.0])?)
///     .with_oracle_best(ArmId(1));
/// assert_eq!(expert.ask(&query)?.expert_arm, Some(ArmId(1)));
/// assert_eq!(expert.asked, 1);
/// query.oracle_best = None;
/// assert!(matches!(expert.ask(&query), Err(HilError::Channel { .. })));
/// # Ok::<(), HilError>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PerfectExpert {
    /// Number of queries answered.
    pub asked: usize,
}

impl PerfectExpert {
    /// The name it reports (`perfect_expert`).
    pub const NAME: &'static str = "perfect_expert";
}

impl QueryChannel for PerfectExpert {
    fn name(&self) -> &str {
        Self::NAME
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        let arm = query.oracle_best.ok_or_else(|| {
            HilError::channel(
                Self::NAME,
                "the environment does not know its best action, so a perfect expert cannot answer",
            )
        })?;
        query.actions.check(arm)?;
        self.asked += 1;
        Ok(Response::action(arm))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ActionSpace, ArmId, Context, Item};

    fn query(best: Option<usize>) -> Query {
        Query {
            t: 3,
            item: Item {
                index: 0,
                label: "x".into(),
                description: None,
            },
            kind: Default::default(),
            actions: ActionSpace::new(["a", "b", "c"]).unwrap(),
            context: Context::new(vec![0.5]).unwrap(),
            oracle_best: best.map(ArmId),
        }
    }

    #[test]
    fn the_perfect_expert_answers_the_oracle_and_counts() {
        let mut e = PerfectExpert::default();
        for best in 0..3 {
            assert_eq!(
                e.ask(&query(Some(best))).unwrap(),
                Response::action(ArmId(best))
            );
        }
        assert_eq!(e.asked, 3);
        assert_eq!(e.name(), "perfect_expert");
    }

    #[test]
    fn an_unknown_or_impossible_best_action_is_an_error() {
        let mut e = PerfectExpert::default();
        assert!(matches!(e.ask(&query(None)), Err(HilError::Channel { .. })));
        assert!(matches!(
            e.ask(&query(Some(3))),
            Err(HilError::ArmOutOfRange { arm: 3, n_arms: 3 })
        ));
        assert_eq!(e.asked, 0);
    }
}
