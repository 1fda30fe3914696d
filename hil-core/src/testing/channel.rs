use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Checker, ConformanceFailure, ConformanceReport, random_context};
use crate::{
    ActionSpace, ArmId, Difficulty, Distraction, Item, Query, QueryChannel, QueryKind, ResponseType,
};

/// Runs the query-channel conformance suite: asks `n` queries covering every
/// response type, difficulty and distraction (over a task-neutral space of six
/// actions, with an oracle answer set, as a simulated environment would) and checks that every response's expert arm
/// indexes the action space and that response times are finite and
/// non-negative.
///
/// Channels that need a person (terminal, web) are checked with a scripted
/// person on the other side by their own tests.
pub fn check_query_channel(
    channel: &mut dyn QueryChannel,
    n: usize,
) -> Result<ConformanceReport, ConformanceFailure> {
    let mut c = Checker::new(channel.name());
    // A task-neutral space: channels must not depend on any one task's
    // action names.
    let actions = ActionSpace::new(["a", "b", "c", "d", "e", "f"])
        .expect("six unique non-empty names form a valid action space");
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    channel.seed(5);
    for i in 0..n {
        let kind = QueryKind {
            response: ResponseType::ALL[i % 3],
            difficulty: Difficulty::ALL[(i / 3) % 2],
            distraction: Distraction::ALL[(i / 6) % 3],
        };
        let best = ArmId(rng.random_range(0..actions.len()));
        let q = Query {
            t: i as u64 + 1,
            item: Item {
                index: i,
                label: "object".into(),
                description: Some("an object near the edge of the table".into()),
            },
            kind,
            actions: actions.clone(),
            context: random_context(&mut rng, 8),
            oracle_best: Some(best),
        };
        let r = c.ok("ask", channel.ask(&q))?;
        c.check(
            "expert arm in range",
            r.expert_arm.is_none_or(|a| a.0 < actions.len()),
            || format!("{:?}", r.expert_arm),
        )?;
        c.check(
            "response time",
            r.response_time_s.is_none_or(|s| s.is_finite() && s >= 0.0),
            || format!("{:?}", r.response_time_s),
        )?;
        if let crate::Answer::Action { arm } = r.answer {
            c.check("answer consistent", r.expert_arm == Some(arm), || {
                format!("answer {arm:?} but expert_arm {:?}", r.expert_arm)
            })?;
        }
    }
    Ok(c.finish())
}
