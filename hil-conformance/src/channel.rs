use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport, random_context};
use hil_core::{ArmId, Item, Query, QueryChannel, QueryKind, Response};

/// Runs the query-channel checks that one instance allows: asks `n`
/// (1 to [`crate::MAX_CHECK_STEPS`]) queries covering every response type, difficulty and distraction (over
/// the default options' six task-neutral actions, with an oracle answer
/// set, as a simulated environment would). Seeded replay, the long run and
/// the destructor check need instances of the suite's own: prefer
/// [`check_query_channel_with`], which builds them.
///
/// Channels that need a person (terminal, web) are checked with a scripted
/// person on the other side by their own tests.
pub fn check_query_channel(
    channel: &mut dyn QueryChannel,
    n: usize,
) -> Result<ConformanceReport, ConformanceFailure> {
    let opts = CheckOptions::default().with_queries(n);
    // n = 0 (or past the limit) is a Build failure naming `queries`.
    opts.validate()
        .map_err(|e| ConformanceFailure::of_factory("query channel", &e))?;
    let mut c = Checker::new(channel.name(), None);
    answers(&mut c, channel, &opts, opts.queries())?;
    c.skip(
        Check::SeededReplay,
        "checked on one instance; check_query_channel_with builds two".into(),
    );
    Ok(c.finish())
}

entry_points! {
    QueryChannel,
    /// Runs every query-channel property on channels built by `make`, stopping
    /// at the first failure.
    ///
    /// Properties, over queries covering every response type, difficulty and
    /// distraction, asked over `opts.actions()` with contexts of
    /// `opts.context_dim()`: [`Check::ExpertArmInRange`] (the query's own
    /// action space, not a fixed task's), [`Check::ResponseTime`] and
    /// [`Check::AnswerConsistent`] over a long run of one instance (`opts.steps()`
    /// queries, 300 by default, or `opts.queries()` if more: a channel that
    /// fails on its 50th query fails); [`Check::SeededReplay`] (a second instance
    /// seeded alike gives the same answers and expert arms to the first
    /// `opts.queries()` queries; response times are not compared, as a human
    /// channel measures them); and [`Check::Destructor`].
    check_query_channel_with,
    /// Runs one query-channel property alone (see [`check_query_channel_with`]).
    check_query_channel_only,
}

fn suite(started: super::Started<'_, dyn QueryChannel>, opts: &CheckOptions) -> super::SuiteResult {
    let super::Started {
        make,
        first: mut a,
        checker: mut c,
    } = started;
    let per_answer = [
        Check::ExpertArmInRange,
        Check::ResponseTime,
        Check::AnswerConsistent,
    ];
    let long = if c.wants_any(&per_answer) {
        opts.steps().max(opts.queries())
    } else {
        opts.queries()
    };
    let ra = answers(&mut c, a.as_mut(), opts, long)?;
    if c.wants(Check::SeededReplay) {
        let mut b = c.ok(Check::Build, make())?;
        let rb = answers(&mut c, b.as_mut(), opts, opts.queries())?;
        let same =
            |x: &Response, y: &Response| x.answer == y.answer && x.expert_arm == y.expert_arm;
        let first = ra.iter().zip(&rb).position(|(x, y)| !same(x, y));
        c.check(Check::SeededReplay, first.is_none(), || {
            let i = first.unwrap_or(0);
            format!(
                "two instances seeded with 5 answered query {i} differently: {:?} vs {:?}",
                ra[i], rb[i]
            )
        })?;
    }
    Ok(c.finish())
}

/// The one place the suite builds a [`Query`].
fn query(i: usize, kind: QueryKind, opts: &CheckOptions, rng: &mut ChaCha8Rng) -> Query {
    let best = ArmId(rng.random_range(0..opts.actions().len()));
    let item = Item::new(i, "object").with_description("an object near the edge of the table");
    Query::new(
        i as u64 + 1,
        item,
        kind,
        opts.actions().clone(),
        random_context(rng, opts.context_dim()),
    )
    .with_oracle_best(best)
}

/// Seeds `channel` with 5 and asks `n` queries; checks each answer.
fn answers(
    c: &mut Checker,
    channel: &mut dyn QueryChannel,
    opts: &CheckOptions,
    n: usize,
) -> Result<Vec<Response>, ConformanceFailure> {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    channel.seed(5);
    let n_actions = opts.actions().len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let q = query(i, super::query_kind(i), opts, &mut rng);
        let r = c.ok(Check::Answers, channel.ask(&q))?;
        c.check(
            Check::ExpertArmInRange,
            r.expert_arm.is_none_or(|a| a.0 < n_actions),
            || {
                format!(
                    "query {i} offered {n_actions} actions ({}), indices 0..{n_actions}, but the channel answered with expert arm {:?}",
                    opts.actions().names().join(", "),
                    r.expert_arm.map(|a| a.0)
                )
            },
        )?;
        c.check(
            Check::ResponseTime,
            r.response_time_s.is_none_or(|s| s.is_finite() && s >= 0.0),
            || format!("query {i}: response_time_s = {:?}", r.response_time_s),
        )?;
        if let hil_core::Answer::Action { arm } = r.answer {
            c.check(Check::AnswerConsistent, r.expert_arm == Some(arm), || {
                format!(
                    "query {i}: answer {arm:?} but expert_arm {:?}",
                    r.expert_arm
                )
            })?;
        }
        out.push(r);
    }
    Ok(out)
}
