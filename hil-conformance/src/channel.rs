use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport, random_context};
use hil_core::{
    ArmId, Difficulty, Distraction, Item, Query, QueryChannel, QueryKind, Response, ResponseType,
};

type Make<'a> = &'a dyn Fn() -> hil_core::Result<Box<dyn QueryChannel>>;

/// Runs the query-channel checks that one instance allows: asks `n`
/// queries covering every response type, difficulty and distraction (over
/// the default options' six task-neutral actions, with an oracle answer
/// set, as a simulated environment would). Seeded replay needs a second
/// instance: prefer [`check_query_channel_with`], which builds them.
///
/// Channels that need a person (terminal, web) are checked with a scripted
/// person on the other side by their own tests.
pub fn check_query_channel(
    channel: &mut dyn QueryChannel,
    n: usize,
) -> Result<ConformanceReport, ConformanceFailure> {
    let opts = CheckOptions::default().with_queries(n.max(1));
    let mut c = Checker::new(channel.name(), None);
    answers(&mut c, channel, &opts)?;
    c.skip(
        Check::SeededReplay,
        "checked on one instance; check_query_channel_with builds two".into(),
    );
    Ok(c.finish())
}

/// Runs every query-channel property on channels built by `make`, stopping
/// at the first failure.
///
/// Properties, over `opts.queries()` queries covering every response type,
/// difficulty and distraction, asked over `opts.actions()` with contexts
/// of `opts.context_dim()`: [`Check::ExpertArmInRange`] (the query's own
/// action space, not a fixed task's), [`Check::ResponseTime`],
/// [`Check::AnswerConsistent`] and [`Check::SeededReplay`] (two instances
/// seeded alike give the same answers and expert arms; response times are
/// not compared, as a human channel measures them).
pub fn check_query_channel_with(
    make: Make<'_>,
    opts: &CheckOptions,
) -> Result<ConformanceReport, ConformanceFailure> {
    run(make, opts, None)
}

/// Runs one query-channel property alone (see [`check_query_channel_with`]).
pub fn check_query_channel_only(
    make: Make<'_>,
    opts: &CheckOptions,
    property: Check,
) -> Result<ConformanceReport, ConformanceFailure> {
    run(make, opts, Some(property))
}

fn run(
    make: Make<'_>,
    opts: &CheckOptions,
    only: Option<Check>,
) -> Result<ConformanceReport, ConformanceFailure> {
    let super::Started {
        make,
        first: mut a,
        checker: mut c,
    } = super::start(make, opts, only)?;
    let ra = answers(&mut c, a.as_mut(), opts)?;
    if c.wants(Check::SeededReplay) {
        let mut b = c.ok(Check::Build, make())?;
        let rb = answers(&mut c, b.as_mut(), opts)?;
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

/// Seeds `channel` with 5 and asks the options' queries; checks each answer.
fn answers(
    c: &mut Checker,
    channel: &mut dyn QueryChannel,
    opts: &CheckOptions,
) -> Result<Vec<Response>, ConformanceFailure> {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    channel.seed(5);
    let n_actions = opts.actions().len();
    let mut out = Vec::with_capacity(opts.queries());
    for i in 0..opts.queries() {
        let kind = QueryKind {
            response: ResponseType::ALL[i % 3],
            difficulty: Difficulty::ALL[(i / 3) % 2],
            distraction: Distraction::ALL[(i / 6) % 3],
        };
        let q = query(i, kind, opts, &mut rng);
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
