use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Checker, ConformanceFailure, ConformanceReport};
use crate::{ArmId, Context, Environment, Item, Outcome};

/// The most items the suite walks through before it calls an episode endless.
const MAX_ITEMS: usize = 10_000;

/// Runs the environment conformance suite on environments built by `make`,
/// with at most `attempts_per_item` attempts at each item.
///
/// Checks: a non-empty action space and a positive context dimension; the
/// same seed replays the same items, contexts and outcomes; contexts have the
/// declared dimension; success probabilities lie in [0, 1]; `best_action`
/// indexes the action space; an arm out of range is an error; calls out of
/// order are errors, not panics; episodes end.
pub fn check_environment(
    make: &dyn Fn() -> crate::Result<Box<dyn Environment>>,
    attempts_per_item: u32,
) -> Result<ConformanceReport, ConformanceFailure> {
    let mut a = make().map_err(|e| ConformanceFailure {
        subject: "<environment factory>".into(),
        check: "build",
        detail: e.to_string(),
    })?;
    let mut c = Checker::new(a.name());
    let mut b = c.ok("build", make())?;
    let n_arms = a.action_space().len();
    let dim = a.context_dim();
    c.check("shape", n_arms >= 1 && dim >= 1, || {
        format!("{n_arms} arms, dimension {dim}")
    })?;

    let ea = run(&mut c, a.as_mut(), 11, attempts_per_item);
    let ea = c.ok("episode", ea)?;
    let eb = run(&mut c, b.as_mut(), 11, attempts_per_item);
    let eb = c.ok("episode", eb)?;
    c.check("replayable", ea == eb, || {
        "two instances reset with the same seed produced different episodes".into()
    })?;
    let again = run(&mut c, a.as_mut(), 11, attempts_per_item);
    let again = c.ok("episode", again)?;
    c.check("replayable", ea == again, || {
        "resetting with the same seed did not replay the episode".into()
    })?;
    c.check("episode has items", !ea.is_empty(), || "no items".into())?;

    // Out-of-range arm.
    c.ok("reset", a.reset(3))?;
    if c.ok("next_item", a.next_item())?.is_some() {
        c.ok("observe", a.observe())?;
        c.check(
            "rejects arm out of range",
            a.execute(ArmId(n_arms)).is_err(),
            || format!("execute accepted arm {n_arms} of {n_arms}"),
        )?;
    }
    // Out-of-order calls on a fresh instance must not panic; errors are fine.
    let mut fresh = c.ok("build", make())?;
    let _ = fresh.observe();
    let _ = fresh.execute(ArmId(0));
    c.check("out-of-order calls do not panic", true, String::new)?;
    Ok(c.finish())
}

type Trace = Vec<(Item, Vec<(Context, Option<ArmId>, Outcome)>)>;

fn run(
    c: &mut Checker,
    env: &mut dyn Environment,
    seed: u64,
    attempts_per_item: u32,
) -> crate::Result<Trace> {
    env.reset(seed)?;
    let n_arms = env.action_space().len();
    let dim = env.context_dim();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut trace = Vec::new();
    while let Some(item) = env.next_item()? {
        if trace.len() >= MAX_ITEMS {
            c.skip("episodes end", format!("stopped after {MAX_ITEMS} items"));
            break;
        }
        if c.check("current item", env.current_item() == Some(&item), || {
            format!(
                "current_item() = {:?} after next_item() = {item:?}",
                env.current_item()
            )
        })
        .is_err()
        {
            return Err(crate::HilError::state(
                env.name(),
                "current_item disagrees with next_item",
            ));
        }
        let mut steps = Vec::new();
        for _ in 0..attempts_per_item.max(1) {
            let x = env.observe()?;
            let best = env.best_action();
            let arm = ArmId(rng.random_range(0..n_arms));
            let out = env.execute(arm)?;
            let ok = x.dim() == dim
                && best.is_none_or(|b| b.0 < n_arms)
                && out
                    .success_probability
                    .is_none_or(|p| (0.0..=1.0).contains(&p));
            if !ok {
                return Err(crate::HilError::state(
                    env.name(),
                    format!(
                        "bad step: context dimension {} (declared {dim}), best action {best:?} of {n_arms}, success probability {:?}",
                        x.dim(),
                        out.success_probability
                    ),
                ));
            }
            let success = out.success;
            steps.push((x, best, out));
            if success {
                break;
            }
        }
        trace.push((item, steps));
    }
    Ok(trace)
}
