use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use serde_json::Value;

use super::{
    Check, CheckOptions, Checker, ConformanceFailure, ConformanceReport, UnderTest, random_context,
};
use hil_core::{
    ActionSpace, ArmId, Attempt, Choice, Context, Decision, DecisionInput, Diagnostics, Feedback,
    HilError, Policy, QueryHistory, Timestep, WorkloadForecast, WorkloadModel,
};

type Make<'a> = &'a dyn Fn() -> hil_core::Result<Box<dyn Policy>>;

/// Runs the policy conformance suite on policies built by `make`, with
/// options taken from the first instance's shape (its arms and dimension);
/// see [`check_policy_with`] for the checks.
pub fn check_policy(make: Make<'_>) -> Result<ConformanceReport, ConformanceFailure> {
    // Guarded, so a panic (in the factory, the shape or the destructor) is
    // a failure like any other; the probe's destructor is checked with the
    // suite's objects.
    let probe = make()
        .and_then(|p| p.guard())
        .map_err(|e| ConformanceFailure::of_factory("policy", &e))?;
    let (n_arms, dim) = (probe.n_arms(), probe.dim());
    let names: Vec<String> = (0..n_arms).map(|i| format!("arm{i}")).collect();
    let Ok(actions) = ActionSpace::new(names) else {
        let subject = probe.name().to_string();
        drop(probe);
        return Err(ConformanceFailure {
            subject,
            check: Check::PolicyShape,
            detail: format!("n_arms = {n_arms}, dim = {dim}"),
            panicked_in: None,
        });
    };
    drop(probe);
    let opts = CheckOptions::default()
        .with_actions(actions)
        .with_context_dim(dim.max(1));
    check_policy_with(make, &opts)
}

entry_points! {
    Policy,
    /// Runs every policy property on policies built by `make` (a factory that
    /// should build for `opts.task_context()`), stopping at the first failure.
    ///
    /// Properties, each on fresh instances: [`Check::PolicyShape`] (the shape
    /// is the options' action space and context dimension),
    /// [`Check::ArmInRange`], [`Check::FiniteDiagnostics`] (naming the field
    /// and the step), [`Check::DiagnosticsCoverArms`] and [`Check::Determinism`]
    /// (two instances seeded alike, driven in lockstep for `opts.steps()`
    /// steps, 300 by default: a long trajectory, so a policy that fails on its
    /// 50th call fails), [`Check::RejectsWrongDimension`] (a
    /// longer and a shorter context, to `decide` and `observe`, refused with
    /// [`HilError::DimensionMismatch`]), [`Check::RejectsArmOutOfRange`]
    /// ([`HilError::ArmOutOfRange`]), [`Check::RejectionHasNoEffect`] (after
    /// the refusals the policy still decides like its untouched twin),
    /// [`Check::Checkpoint`] (skipped only when a fresh instance's `save`
    /// returns [`HilError::Unsupported`], what the trait's default `save` does;
    /// the state saved after `restore` must equal the state restored, and a
    /// key that does not round-trip is named) and [`Check::Destructor`].
    check_policy_with,
    /// Runs one policy property alone (see [`check_policy_with`]); what
    /// [`crate::conformance_tests!`] calls for each generated test.
    check_policy_only,
}

fn suite(started: super::Started<'_, dyn Policy>, opts: &CheckOptions) -> super::SuiteResult {
    let super::Started {
        make,
        first,
        checker: mut c,
    } = started;
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
        c.ok(Check::Checkpoint, r.restore(state.clone()))?;
        let again = c.ok(Check::Checkpoint, r.save())?;
        if let Some((key, saved, resaved)) = first_difference(&state, &again) {
            return Err(c.fail(
                Check::Checkpoint,
                format!(
                    "the saved key `{key}` did not round-trip: saved {saved}, but the restored instance saves {resaved}; restore() does not set it from the checkpoint (or save() writes it in a form restore() reads back differently)"
                ),
            ));
        }
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

/// The first field of `diag` that is not finite
/// ([`Diagnostics::first_non_finite`], what the session loop refuses), or a
/// negative bonus: its path (`arms[2].estimate`, `gap`, `extra.agreement`)
/// and value.
fn ill_formed(diag: &Diagnostics) -> Option<(String, f64)> {
    diag.first_non_finite().or_else(|| {
        let (i, a) = diag.arms.iter().enumerate().find(|(_, a)| a.bonus < 0.0)?;
        Some((format!("arms[{i}].bonus"), a.bonus))
    })
}

/// The first place where two saved states differ: its key path
/// (`counts[1][0]`, `rng.word_pos`; `` for the whole value) and both
/// values, as JSON.
fn first_difference(a: &Value, b: &Value) -> Option<(String, String, String)> {
    fn walk(path: String, a: &Value, b: &Value) -> Option<(String, String, String)> {
        let join = |key: &str| {
            if path.is_empty() {
                key.to_string()
            } else {
                format!("{path}.{key}")
            }
        };
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                let keys = x.keys().chain(y.keys().filter(|k| !x.contains_key(*k)));
                keys.map(|k| match (x.get(k), y.get(k)) {
                    (Some(u), Some(v)) => walk(join(k), u, v),
                    (u, v) => Some((join(k), show(u), show(v))),
                })
                .find_map(|d| d)
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
                .iter()
                .zip(y)
                .enumerate()
                .find_map(|(i, (u, v))| walk(format!("{path}[{i}]"), u, v)),
            _ if a == b => None,
            _ => Some((path, a.to_string(), b.to_string())),
        }
    }
    fn show(v: Option<&Value>) -> String {
        v.map_or_else(|| "nothing".to_string(), Value::to_string)
    }
    walk(String::new(), a, b)
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
    Feedback::new(Attempt {
        context: x,
        arm,
        reward,
        t,
    })
    .from_expert(from_expert)
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
    let at_t = |mut f: ConformanceFailure| {
        f.detail = format!("at t = {t}: {}", f.detail);
        f
    };
    let d = c
        .ok(
            err,
            p.decide(&decision_input(x, t, item, attempt, model, &s.history)),
        )
        .map_err(at_t)?;
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
    let bad = ill_formed(diag);
    c.check(Check::FiniteDiagnostics, bad.is_none(), || {
        let (field, v) = bad.clone().unwrap_or_default();
        let what = if v.is_finite() {
            "negative"
        } else {
            "not finite"
        };
        format!("the decision at t = {t} reports diagnostics.{field} = {v} ({what})")
    })?;
    c.check(
        Check::DiagnosticsCoverArms,
        diag.arms.is_empty() || diag.arms.len() == n,
        || format!("{} entries for {n} arms", diag.arms.len()),
    )?;
    let queried = matches!(d.choice, Choice::Query { .. });
    c.ok(err, p.observe(&feedback(x, arm, reward, t, queried)))
        .map_err(at_t)?;
    if let Choice::Query { kind, .. } = d.choice {
        c.ok(err, s.history.push(t, kind))?;
    }
    s.t = t;
    s.item = item;
    s.attempt = attempt;
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::ArmDiagnostics;
    use serde_json::json;

    #[test]
    fn ill_formed_diagnostics_are_named_by_field() {
        let ok = Diagnostics::new().with_arms(vec![ArmDiagnostics::new(0.5, 0.1, 0.6); 2]);
        assert_eq!(ill_formed(&ok), None);
        let nan = ok.clone().with_arms(vec![
            ArmDiagnostics::new(0.5, 0.1, 0.6),
            ArmDiagnostics::new(f64::NAN, 0.1, 0.6),
        ]);
        assert_eq!(
            ill_formed(&nan).map(|f| f.0).as_deref(),
            Some("arms[1].estimate")
        );
        let negative = ok
            .clone()
            .with_arms(vec![ArmDiagnostics::new(0.5, -0.1, 0.4)]);
        assert_eq!(ill_formed(&negative), Some(("arms[0].bonus".into(), -0.1)));
        let gap = ok.clone().with_gap(f64::INFINITY);
        assert_eq!(ill_formed(&gap).map(|f| f.0).as_deref(), Some("gap"));
        let extra = ok.with_extra("agreement", f64::NAN);
        assert_eq!(
            ill_formed(&extra).map(|f| f.0).as_deref(),
            Some("extra.agreement")
        );
    }

    #[test]
    fn the_first_difference_of_two_states_names_its_key() {
        let a = json!({"counts": [[1.0, 2.0], [0.0, 1.0]], "rng": {"seed": 3, "pos": "12"}});
        assert_eq!(first_difference(&a, &a), None);
        let mut b = a.clone();
        b["rng"]["pos"] = json!(12.0);
        assert_eq!(
            first_difference(&a, &b),
            Some(("rng.pos".into(), "\"12\"".into(), "12.0".into()))
        );
        let mut b = a.clone();
        b["counts"][1][0] = json!(5.0);
        assert_eq!(first_difference(&a, &b).unwrap().0, "counts[1][0]");
        let mut b = a.clone();
        b.as_object_mut().unwrap().remove("counts");
        assert_eq!(
            first_difference(&a, &b).map(|d| (d.0, d.2)),
            Some(("counts".into(), "nothing".into()))
        );
    }
}
