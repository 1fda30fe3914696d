use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport};
use hil_core::{ArmId, Context, Environment, HilError, Item, Outcome};

/// The most items the suite walks through before it calls an episode endless.
const MAX_ITEMS: usize = 10_000;

type Make<'a> = &'a dyn Fn() -> hil_core::Result<Box<dyn Environment>>;

/// Runs the environment conformance suite on environments built by `make`,
/// with at most `attempts_per_item` attempts at each item (1 to
/// [`hil_config::limits::ATTEMPTS_PER_ITEM`]: outside that, a
/// [`Check::Build`](crate::Check::Build) failure naming `attempts`); see
/// [`check_environment_with`] for the checks.
pub fn check_environment(
    make: Make<'_>,
    attempts_per_item: u32,
) -> Result<ConformanceReport, ConformanceFailure> {
    check_environment_with(
        make,
        &CheckOptions::default().with_attempts(attempts_per_item),
    )
}

entry_points! {
    Environment,
    /// Runs every environment property on environments built by `make`,
    /// stopping at the first failure.
    ///
    /// Properties: [`Check::EnvironmentShape`]; over a long trajectory (episodes
    /// of consecutive seeds on one instance until `opts.steps()` attempts, 300
    /// by default, are executed, so an environment that fails on its 50th call
    /// fails) and three episodes of seed 11 (two instances, and one of them
    /// reset again) [`Check::EpisodeHasItems`],
    /// [`Check::EpisodesEnd`], [`Check::CurrentItem`],
    /// [`Check::ContextDimension`], [`Check::SuccessProbability`],
    /// [`Check::BestActionInRange`] and [`Check::Replayable`];
    /// [`Check::ExecuteRejectsArmOutOfRange`] (refused with
    /// [`HilError::ArmOutOfRange`], and the attempt can still be executed,
    /// with the outcome of an instance that never saw the bad arm); and
    /// [`Check::OutOfOrderCalls`] (`observe` and `execute` before `next_item`,
    /// and `execute` before `observe`, refused with [`HilError::State`]; a
    /// later `reset` replays the episode); and [`Check::Destructor`].
    check_environment_with,
    /// Runs one environment property alone (see [`check_environment_with`]).
    check_environment_only,
}

/// The checks made at every step of an episode.
const STEP_CHECKS: [Check; 5] = [
    Check::EpisodesEnd,
    Check::CurrentItem,
    Check::ContextDimension,
    Check::SuccessProbability,
    Check::BestActionInRange,
];

fn suite(started: super::Started<'_, dyn Environment>, opts: &CheckOptions) -> super::SuiteResult {
    let super::Started {
        make,
        first: mut a,
        checker: mut c,
    } = started;
    let build = |c: &Checker| c.ok(Check::Build, make());
    let n_arms = a.action_space().len();
    let dim = a.context_dim();
    c.check(Check::EnvironmentShape, n_arms >= 1 && dim >= 1, || {
        format!("{n_arms} arms, context dimension {dim}")
    })?;
    if n_arms == 0 {
        // Nothing below can act without an arm.
        return Err(c.fail(Check::EpisodeRuns, "the action space is empty".into()));
    }
    let attempts = opts.attempts();

    let ea = run_episode(&mut c, a.as_mut(), 11, attempts)?;
    c.check(Check::EpisodeHasItems, !ea.is_empty(), || {
        "reset(11) gave an episode without items".into()
    })?;
    if c.wants_any(&STEP_CHECKS) && !ea.is_empty() {
        // The long trajectory: episodes of seeds 12, 13, ... on the same
        // instance until `opts.steps()` attempts have been executed.
        let mut executed = attempts_in(&ea);
        let mut seed = 12;
        while executed < opts.steps() {
            executed += attempts_in(&run_episode(&mut c, a.as_mut(), seed, attempts)?);
            seed += 1;
        }
    }
    if c.wants(Check::Replayable) {
        let mut b = build(&c)?;
        let eb = run_episode(&mut c, b.as_mut(), 11, attempts)?;
        c.check(Check::Replayable, ea == eb, || {
            format!(
                "two instances reset with seed 11 produced different episodes ({})",
                first_difference(&ea, &eb)
            )
        })?;
        let again = run_episode(&mut c, a.as_mut(), 11, attempts)?;
        c.check(Check::Replayable, ea == again, || {
            format!(
                "resetting with seed 11 again did not replay the episode ({})",
                first_difference(&ea, &again)
            )
        })?;
    }

    // An arm out of range: refused, and the attempt is intact.
    if c.wants(Check::ExecuteRejectsArmOutOfRange) {
        let check = Check::ExecuteRejectsArmOutOfRange;
        let (mut a, mut b) = (build(&c)?, build(&c)?);
        let mut pair = [a.as_mut(), b.as_mut()];
        for e in &mut pair {
            c.ok(Check::EpisodeRuns, e.reset(3))?;
            c.ok(Check::EpisodeRuns, e.next_item())?;
            c.ok(Check::EpisodeRuns, e.observe())?;
        }
        let [a, b] = pair;
        if a.current_item().is_some() {
            let r = a.execute(ArmId(n_arms));
            c.refused(
                check,
                &format!("execute(arm {n_arms}) (the action space has arms 0..{n_arms})"),
                &format!("HilError::ArmOutOfRange {{ arm: {n_arms}, n_arms: {n_arms} }}"),
                r,
                |e| matches!(e, HilError::ArmOutOfRange { arm, n_arms: n } if *arm == n_arms && *n == n_arms),
            )?;
            let after = a.execute(ArmId(0)).map_err(|e| {
                c.fail(
                    check,
                    format!(
                        "after refusing arm {n_arms}, execute(arm 0) on the same observation failed: {e}"
                    ),
                )
            })?;
            let untouched = c.ok(Check::EpisodeRuns, b.execute(ArmId(0)))?;
            c.check(check, after == untouched, || {
                format!(
                    "after refusing arm {n_arms}, execute(arm 0) gave {after:?}; an instance that never saw the bad arm gave {untouched:?}"
                )
            })?;
        }
    }

    // Calls out of order: refused as such, and harmless.
    if c.wants(Check::OutOfOrderCalls) {
        let check = Check::OutOfOrderCalls;
        let is_state = |e: &HilError| matches!(e, HilError::State { .. });
        let kind = "HilError::State";
        let mut fresh = build(&c)?;
        let r = fresh.observe();
        c.refused(check, "observe before next_item", kind, r, is_state)?;
        let r = fresh.execute(ArmId(0));
        c.refused(check, "execute before next_item", kind, r, is_state)?;
        c.ok(Check::EpisodeRuns, fresh.reset(11))?;
        if c.ok(Check::EpisodeRuns, fresh.next_item())?.is_some() {
            let r = fresh.execute(ArmId(0));
            c.refused(check, "execute before observe", kind, r, is_state)?;
        }
        let replay = run_episode(&mut c, fresh.as_mut(), 11, attempts)?;
        c.check(check, replay == ea, || {
            format!(
                "after refused out-of-order calls, reset(11) did not give the usual episode ({})",
                first_difference(&ea, &replay)
            )
        })?;
    }
    Ok(c.finish())
}

type Trace = Vec<(Item, Vec<(Context, Option<ArmId>, Outcome)>)>;

/// How many attempts an episode executed.
fn attempts_in(trace: &Trace) -> usize {
    trace.iter().map(|(_, steps)| steps.len()).sum()
}

/// Where two traces first differ, for failure messages.
fn first_difference(a: &Trace, b: &Trace) -> String {
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        if x != y {
            return format!("first at item {i}: {x:?} vs {y:?}");
        }
    }
    format!("{} items vs {}", a.len(), b.len())
}

/// One episode of seed `seed` with seeded random arms.
fn run_episode(
    c: &mut Checker,
    env: &mut dyn Environment,
    seed: u64,
    attempts_per_item: u32,
) -> Result<Trace, ConformanceFailure> {
    c.ok(Check::EpisodeRuns, env.reset(seed))?;
    let n_arms = env.action_space().len();
    let dim = env.context_dim();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut trace = Vec::new();
    while let Some(item) = c.ok(Check::EpisodeRuns, env.next_item())? {
        if trace.len() >= MAX_ITEMS {
            c.check(Check::EpisodesEnd, false, || {
                format!("next_item still returned items after {MAX_ITEMS}")
            })?;
            break;
        }
        c.check(
            Check::CurrentItem,
            env.current_item() == Some(&item),
            || {
                format!(
                    "current_item() = {:?} after next_item() = {item:?}",
                    env.current_item()
                )
            },
        )?;
        let mut steps = Vec::new();
        for _ in 0..attempts_per_item.max(1) {
            let x = c.ok(Check::EpisodeRuns, env.observe())?;
            c.check(Check::ContextDimension, x.dim() == dim, || {
                format!(
                    "observe returned a context of dimension {} at item {}; context_dim() is {dim}",
                    x.dim(),
                    item.index
                )
            })?;
            let best = env.best_action();
            c.check(
                Check::BestActionInRange,
                best.is_none_or(|b| b.0 < n_arms),
                || format!("best_action() = {best:?}, but the action space has arms 0..{n_arms}"),
            )?;
            let arm = ArmId(rng.random_range(0..n_arms));
            let out = c.ok(Check::EpisodeRuns, env.execute(arm))?;
            c.check(
                Check::SuccessProbability,
                out.success_probability
                    .is_none_or(|p| (0.0..=1.0).contains(&p)),
                || {
                    format!(
                        "execute({arm:?}) reported success probability {:?}",
                        out.success_probability
                    )
                },
            )?;
            let success = out.success;
            steps.push((x, best, out));
            if success {
                break;
            }
        }
        trace.push((item, steps));
    }
    c.check(Check::EpisodesEnd, true, String::new)?;
    Ok(trace)
}
