use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::fixtures::CountingWorkload;
use super::{Checker, ConformanceFailure, ConformanceReport, random_context};
use crate::{
    ArmId, Choice, Context, Decision, DecisionInput, Feedback, Policy, QueryHistory,
    WorkloadForecast, WorkloadModel,
};

/// Runs the policy conformance suite on policies built by `make`.
///
/// Checks: decisions index the arms; diagnostics are finite; two instances
/// seeded alike decide alike; a context of the wrong dimension and an arm
/// out of range are errors, not panics; a checkpoint restored into a fresh
/// instance continues identically (skipped if the policy cannot checkpoint).
pub fn check_policy(
    make: &dyn Fn() -> crate::Result<Box<dyn Policy>>,
) -> Result<ConformanceReport, ConformanceFailure> {
    let mut a = make().map_err(|e| fail_build(e.to_string()))?;
    let mut c = Checker::new(a.name());
    let mut b = c.ok("build", make())?;
    let (n_arms, dim) = (a.n_arms(), a.dim());
    c.check("shape", n_arms >= 1 && dim >= 1, || {
        format!("n_arms = {n_arms}, dim = {dim}")
    })?;
    c.check("shape", b.n_arms() == n_arms && b.dim() == dim, || {
        "two instances from the same factory disagree on their shape".into()
    })?;
    a.seed(42);
    b.seed(42);
    let model = CountingWorkload::new(0.1);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut twin_a = Twin::default();
    let mut twin_b = Twin::default();
    lockstep(
        &mut c,
        "determinism",
        (a.as_mut(), &mut twin_a),
        (b.as_mut(), &mut twin_b),
        &model,
        &mut rng,
        40,
    )?;
    let (history, state) = (&twin_a.history, &twin_a.state);

    // Bad input.
    let wrong = Context::new(vec![0.5; dim + 1]).expect("finite");
    let input = DecisionInput {
        context: &wrong,
        t: state.t + 1,
        item_index: state.item,
        items_seen: state.item,
        attempt: 0,
        workload: WorkloadForecast::new(Some(&model), 0.5, history, state.t + 1),
    };
    c.check("rejects wrong dimension", a.decide(&input).is_err(), || {
        format!(
            "decide accepted a context of dimension {} (policy has {dim})",
            dim + 1
        )
    })?;
    let fb = Feedback {
        context: &wrong,
        arm: ArmId(0),
        reward: 1.0,
        t: state.t + 1,
        from_expert: false,
    };
    c.check("rejects wrong dimension", a.observe(&fb).is_err(), || {
        "observe accepted a context of the wrong dimension".into()
    })?;
    let x = random_context(&mut rng, dim);
    let fb = Feedback {
        context: &x,
        arm: ArmId(n_arms),
        reward: 1.0,
        t: state.t + 1,
        from_expert: false,
    };
    c.check("rejects arm out of range", a.observe(&fb).is_err(), || {
        format!("observe accepted arm {n_arms} of {n_arms}")
    })?;

    // Checkpoint and restore.
    match a.save() {
        Err(e) => c.skip("checkpoint", e.to_string()),
        Ok(state_json) => {
            let mut r = c.ok("checkpoint", make())?;
            r.seed(1234); // the restored RNG state must override this
            c.ok("checkpoint", r.restore(state_json))?;
            let mut twin_r = twin_a.clone();
            lockstep(
                &mut c,
                "checkpoint",
                (a.as_mut(), &mut twin_a),
                (r.as_mut(), &mut twin_r),
                &model,
                &mut rng,
                20,
            )?;
        }
    }
    Ok(c.finish())
}

fn fail_build(why: String) -> ConformanceFailure {
    ConformanceFailure {
        subject: "<policy factory>".into(),
        check: "build",
        detail: why,
    }
}

/// Drives two policies with identical inputs and checks they decide alike.
fn lockstep(
    c: &mut Checker,
    check: &'static str,
    (a, ta): (&mut dyn Policy, &mut Twin),
    (b, tb): (&mut dyn Policy, &mut Twin),
    model: &dyn WorkloadModel,
    rng: &mut ChaCha8Rng,
    steps: usize,
) -> Result<(), ConformanceFailure> {
    for _ in 0..steps {
        let dim = a.dim();
        let x = random_context(rng, dim);
        let reward = f64::from(rng.random_bool(0.5));
        let da = drive(
            c,
            a,
            &x,
            model,
            &mut ta.history,
            &mut ta.state,
            reward,
            true,
        )?;
        let db = drive(
            c,
            b,
            &x,
            model,
            &mut tb.history,
            &mut tb.state,
            reward,
            true,
        )?;
        c.check(check, da == db, || {
            format!("same inputs, different decisions: {da:?} vs {db:?}")
        })?;
    }
    Ok(())
}

/// The inputs one policy of a lockstep pair has seen.
#[derive(Clone, Default)]
struct Twin {
    history: QueryHistory,
    state: DriveState,
}

#[derive(Clone, Default)]
struct DriveState {
    t: u64,
    item: usize,
    attempt: u32,
}

/// One decide/observe round at the next timestep. Time and history advance
/// only when `advance` is set, so both twins of a determinism pair see the
/// same inputs.
#[allow(clippy::too_many_arguments)]
fn drive(
    c: &mut Checker,
    p: &mut dyn Policy,
    x: &Context,
    model: &dyn WorkloadModel,
    history: &mut QueryHistory,
    s: &mut DriveState,
    reward: f64,
    advance: bool,
) -> Result<Decision, ConformanceFailure> {
    let t = s.t + 1;
    // Three attempts per item, so first-attempt rules (ExpDecay) are exercised.
    let (item, attempt) = if s.t == 0 {
        (0, 0)
    } else if s.attempt >= 2 {
        (s.item + 1, 0)
    } else {
        (s.item, s.attempt + 1)
    };
    let input = DecisionInput {
        context: x,
        t,
        item_index: item,
        items_seen: item,
        attempt,
        workload: WorkloadForecast::new(Some(model), 0.5, history, t),
    };
    let d = c.ok("decide", p.decide(&input))?;
    let n = p.n_arms();
    let arm = match d.choice {
        Choice::Act { arm } => arm,
        Choice::Query { fallback, .. } => fallback,
    };
    c.check("arm in range", arm.0 < n, || {
        format!("arm {} of {n}", arm.0)
    })?;
    let diag = &d.diagnostics;
    let finite = diag.arms.iter().all(|a| {
        a.estimate.is_finite() && a.bonus.is_finite() && a.ucb.is_finite() && a.bonus >= 0.0
    }) && [
        diag.gap,
        diag.threshold,
        diag.query_probability,
        diag.workload_forecast,
    ]
    .iter()
    .all(|v| v.is_none_or(f64::is_finite));
    c.check("finite diagnostics", finite, || format!("{diag:?}"))?;
    c.check(
        "diagnostics cover every arm",
        diag.arms.is_empty() || diag.arms.len() == n,
        || format!("{} entries for {n} arms", diag.arms.len()),
    )?;
    let queried = matches!(d.choice, Choice::Query { .. });
    c.ok(
        "observe",
        p.observe(&Feedback {
            context: x,
            arm,
            reward,
            t,
            from_expert: queried,
        }),
    )?;
    if advance {
        if let Choice::Query { kind, .. } = d.choice {
            c.ok("decide", history.push(t, kind))?;
        }
        *s = DriveState { t, item, attempt };
    }
    Ok(d)
}
