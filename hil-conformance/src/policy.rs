use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport, random_context};
use hil_core::{
    ActionSpace, ArmId, Choice, Context, Decision, DecisionInput, Feedback, HilError, Policy,
    QueryHistory, Timestep, WorkloadForecast, WorkloadModel,
};

type Make<'a> = &'a dyn Fn() -> hil_core::Result<Box<dyn Policy>>;

/// Runs the policy conformance suite on policies built by `make`, with
/// options taken from the first instance's shape (its arms and dimension);
/// see [`check_policy_with`] for the checks.
pub fn check_policy(make: Make<'_>) -> Result<ConformanceReport, ConformanceFailure> {
    let probe = make().map_err(|e| ConformanceFailure::of_factory("policy", &e))?;
    let (n_arms, dim) = (probe.n_arms(), probe.dim());
    let names: Vec<String> = (0..n_arms).map(|i| format!("arm{i}")).collect();
    let Ok(actions) = ActionSpace::new(names) else {
        return Err(ConformanceFailure {
            subject: probe.name().to_string(),
            check: Check::PolicyShape,
            detail: format!("n_arms = {n_arms}, dim = {dim}"),
        });
    };
    let opts = CheckOptions::default()
        .with_actions(actions)
        .with_context_dim(dim.max(1));
    check_policy_with(make, &opts)
}

/// Runs every policy property on policies built by `make` (a factory that
/// should build for `opts.build_context()`), stopping at the first failure.
///
/// Properties, each on fresh instances: [`Check::PolicyShape`] (the shape
/// is the options' action space and context dimension),
/// [`Check::ArmInRange`], [`Check::FiniteDiagnostics`],
/// [`Check::DiagnosticsCoverArms`], [`Check::Determinism`] (two instances
/// seeded alike, driven in lockstep), [`Check::RejectsWrongDimension`] (a
/// longer and a shorter context, to `decide` and `observe`, refused with
/// [`HilError::DimensionMismatch`]), [`Check::RejectsArmOutOfRange`]
/// ([`HilError::ArmOutOfRange`]), [`Check::RejectionHasNoEffect`] (after
/// the refusals the policy still decides like its untouched twin) and
/// [`Check::Checkpoint`] (skipped only when a fresh instance's `save`
/// returns [`HilError::Unsupported`], what the trait's default `save` does).
pub fn check_policy_with(
    make: Make<'_>,
    opts: &CheckOptions,
) -> Result<ConformanceReport, ConformanceFailure> {
    run(make, opts, None)
}

/// Runs one policy property alone (see [`check_policy_with`]); what
/// [`crate::conformance_tests!`] calls for each generated test.
pub fn check_policy_only(
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
        first,
        checker: mut c,
    } = super::start(make, opts, only)?;
    drop(first);
    let build = |c: &Checker| c.ok(Check::Build, make());

    // Shape.
    if c.wants(Check::PolicyShape) {
        let (a, b) = (build(&c)?, build(&c)?);
        let (n_arms, dim) = (a.n_arms(), a.dim());
        c.check(Check::PolicyShape, n_arms >= 1 && dim >= 1, || {
            format!("n_arms = {n_arms}, dim = {dim}")
        })?;
        let (want_arms, want_dim) = (opts.actions().len(), opts.context_dim());
        c.check(
            Check::PolicyShape,
            n_arms == want_arms && dim == want_dim,
            || {
                format!(
                    "built with {n_arms} arms and dimension {dim}, but the build context offered {want_arms} arms and dimension {want_dim}"
                )
            },
        )?;
        c.check(
            Check::PolicyShape,
            b.n_arms() == n_arms && b.dim() == dim,
            || "two instances from the same factory disagree on their shape".into(),
        )?;
    }

    let mut rng = ChaCha8Rng::seed_from_u64(7);

    // Well-formed, deterministic decisions.
    let lockstep_checks = [
        Check::ArmInRange,
        Check::FiniteDiagnostics,
        Check::DiagnosticsCoverArms,
        Check::Determinism,
    ];
    if lockstep_checks.iter().any(|&k| c.wants(k)) {
        let (mut a, mut b) = (build(&c)?, build(&c)?);
        a.seed(42);
        b.seed(42);
        let mut pair = Pair::new(a.as_mut(), b.as_mut());
        pair.run(
            &mut c,
            opts,
            &mut rng,
            opts.steps(),
            Some(Check::Determinism),
            Check::PolicyDecides,
        )?;
    }

    // Bad input: refused with the right kind, and without side effects.
    for kind in [Check::RejectsWrongDimension, Check::RejectsArmOutOfRange] {
        if !(c.wants(kind) || c.wants(Check::RejectionHasNoEffect)) {
            continue;
        }
        let (mut a, mut b) = (build(&c)?, build(&c)?);
        a.seed(42);
        b.seed(42);
        let mut pair = Pair::new(a.as_mut(), b.as_mut());
        pair.run(&mut c, opts, &mut rng, 10, None, Check::PolicyDecides)?;
        let (t, item) = (pair.ta.t + 1, pair.ta.item);
        let p = &mut *pair.a;
        let (n_arms, dim) = (p.n_arms(), p.dim());
        if kind == Check::RejectsWrongDimension {
            let mut wrong = vec![dim + 1];
            if dim > 1 {
                wrong.push(dim - 1);
            }
            for got in wrong {
                let x = Context::new(vec![0.5; got]).expect("finite");
                let is_mismatch = |e: &HilError| matches!(e, HilError::DimensionMismatch { expected, got: g } if *expected == dim && *g == got);
                let kind_name =
                    format!("HilError::DimensionMismatch {{ expected: {dim}, got: {got} }}");
                let r = p.decide(&decision_input(
                    &x,
                    t,
                    item,
                    0,
                    opts.workload(),
                    &pair.ta.history,
                ));
                c.refused(
                    kind,
                    &format!("decide with a context of dimension {got} (policy has {dim})"),
                    &kind_name,
                    r,
                    is_mismatch,
                )?;
                let r = p.observe(&feedback(&x, ArmId(0), 1.0, t, false));
                c.refused(
                    kind,
                    &format!("observe with a context of dimension {got} (policy has {dim})"),
                    &kind_name,
                    r,
                    is_mismatch,
                )?;
            }
        } else {
            let x = random_context(&mut rng, dim);
            let r = p.observe(&feedback(&x, ArmId(n_arms), 1.0, t, false));
            c.refused(
                kind,
                &format!("observe with arm {n_arms} (the policy has arms 0..{n_arms})"),
                &format!("HilError::ArmOutOfRange {{ arm: {n_arms}, n_arms: {n_arms} }}"),
                r,
                |e| matches!(e, HilError::ArmOutOfRange { arm, n_arms: n } if *arm == n_arms && *n == n_arms),
            )?;
        }
        if c.wants(Check::RejectionHasNoEffect) {
            pair.run(
                &mut c,
                opts,
                &mut rng,
                20,
                Some(Check::RejectionHasNoEffect),
                Check::RejectionHasNoEffect,
            )?;
        }
    }

    // Checkpoint and restore.
    if c.wants(Check::Checkpoint) {
        let mut a = build(&c)?;
        a.seed(42);
        match a.save() {
            Err(e @ HilError::Unsupported { .. }) => {
                c.skip(Check::Checkpoint, e.to_string());
                return Ok(c.finish());
            }
            Err(e) => {
                return Err(c.fail(
                    Check::Checkpoint,
                    format!(
                        "save() on a fresh instance failed: {}; a policy that cannot checkpoint returns HilError::Unsupported (the trait's default)",
                        super::describe_error(&e)
                    ),
                ));
            }
            Ok(_) => {}
        }
        let half = (opts.steps() / 2).max(1);
        let mut ta = Twin::default();
        for _ in 0..half {
            let x = random_context(&mut rng, a.dim());
            let reward = f64::from(rng.random_bool(0.5));
            drive(
                &mut c,
                a.as_mut(),
                &x,
                opts.workload(),
                &mut ta,
                reward,
                Check::PolicyDecides,
            )?;
        }
        let state = c.ok(Check::Checkpoint, a.save())?;
        let mut r = build(&c)?;
        r.seed(1234); // the restored RNG state must override this
        c.ok(Check::Checkpoint, r.restore(state))?;
        let mut pair = Pair {
            a: a.as_mut(),
            b: r.as_mut(),
            tb: ta.clone(),
            ta,
        };
        pair.run(
            &mut c,
            opts,
            &mut rng,
            half,
            Some(Check::Checkpoint),
            Check::Checkpoint,
        )?;
    }
    Ok(c.finish())
}

/// The one place the suite builds a [`DecisionInput`].
fn decision_input<'a>(
    x: &'a Context,
    t: Timestep,
    item: usize,
    attempt: u32,
    model: &'a dyn WorkloadModel,
    history: &'a QueryHistory,
) -> DecisionInput<'a> {
    DecisionInput::new(x, t, WorkloadForecast::new(Some(model), 0.5, history, t))
        .at_item(item, item, attempt)
}

/// The one place the suite builds a [`Feedback`].
fn feedback(x: &Context, arm: ArmId, reward: f64, t: Timestep, from_expert: bool) -> Feedback<'_> {
    Feedback::new(x, arm, reward, t).from_expert(from_expert)
}

/// Two policies fed identical inputs, with the inputs each has seen.
struct Pair<'p> {
    a: &'p mut dyn Policy,
    b: &'p mut dyn Policy,
    ta: Twin,
    tb: Twin,
}

impl<'p> Pair<'p> {
    fn new(a: &'p mut dyn Policy, b: &'p mut dyn Policy) -> Self {
        Self {
            a,
            b,
            ta: Twin::default(),
            tb: Twin::default(),
        }
    }

    /// Drives both for `steps` rounds with the same inputs; with `compare`,
    /// different decisions fail that check. Errors fail `err`.
    fn run(
        &mut self,
        c: &mut Checker,
        opts: &CheckOptions,
        rng: &mut ChaCha8Rng,
        steps: usize,
        compare: Option<Check>,
        err: Check,
    ) -> Result<(), ConformanceFailure> {
        for _ in 0..steps {
            let x = random_context(rng, self.a.dim());
            let reward = f64::from(rng.random_bool(0.5));
            let da = drive(c, self.a, &x, opts.workload(), &mut self.ta, reward, err)?;
            let db = drive(c, self.b, &x, opts.workload(), &mut self.tb, reward, err)?;
            if let Some(check) = compare {
                c.check(check, da == db, || {
                    format!(
                        "same seed and inputs, different decisions at t = {}: {da:?} vs {db:?}",
                        self.ta.t
                    )
                })?;
            }
        }
        Ok(())
    }
}

/// The inputs one policy has seen.
#[derive(Clone, Default)]
struct Twin {
    history: QueryHistory,
    t: Timestep,
    item: usize,
    attempt: u32,
}

/// One decide/observe round at the next timestep; checks the decision.
fn drive(
    c: &mut Checker,
    p: &mut dyn Policy,
    x: &Context,
    model: &dyn WorkloadModel,
    s: &mut Twin,
    reward: f64,
    err: Check,
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
    let d = c.ok(
        err,
        p.decide(&decision_input(x, t, item, attempt, model, &s.history)),
    )?;
    let n = p.n_arms();
    let arm = match d.choice {
        Choice::Act { arm } => arm,
        Choice::Query { fallback, .. } => fallback,
    };
    c.check(Check::ArmInRange, arm.0 < n, || {
        format!(
            "decide returned arm {} at t = {t}, but the policy has arms 0..{n}",
            arm.0
        )
    })?;
    if arm.0 >= n {
        // Only reached when this property is not being checked: feeding
        // the bad arm back would fail an unrelated check.
        return Err(c.fail(err, format!("decide returned arm {} of {n}", arm.0)));
    }
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
    c.check(Check::FiniteDiagnostics, finite, || {
        format!("at t = {t}: {diag:?}")
    })?;
    c.check(
        Check::DiagnosticsCoverArms,
        diag.arms.is_empty() || diag.arms.len() == n,
        || format!("{} entries for {n} arms", diag.arms.len()),
    )?;
    let queried = matches!(d.choice, Choice::Query { .. });
    c.ok(err, p.observe(&feedback(x, arm, reward, t, queried)))?;
    if let Choice::Query { kind, .. } = d.choice {
        c.ok(err, s.history.push(t, kind))?;
    }
    s.t = t;
    s.item = item;
    s.attempt = attempt;
    Ok(d)
}
