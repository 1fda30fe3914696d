//! Every conformance check can fail: each deliberately broken
//! implementation of `hil_conformance::broken` is caught by exactly the
//! check its defect names, both by the whole suite and by that property
//! run alone; the unbroken implementations pass; and the tests generated
//! by `conformance_tests!` fail naming the property.

use std::collections::HashSet;

use hil_conformance::broken::{
    self, ChannelDefect, EnvironmentDefect, PolicyDefect, WorkloadDefect,
};
use hil_conformance::{
    Check, CheckOptions, ConformanceFailure, ConformanceReport, Subject, assert_conforms,
    check_environment_only, check_environment_with, check_policy_only, check_policy_with,
    check_query_channel_only, check_query_channel_with, check_workload_model_built_only,
    check_workload_model_built_with, check_workload_model_with,
};
use hil_core::HilError;

/// Three actions, so a channel that assumes the feeding task's six is caught.
fn options() -> CheckOptions {
    CheckOptions::default()
        .with_actions(hil_core::ActionSpace::new(["grasp", "push", "lift"]).unwrap())
        .with_context_dim(4)
}

type Run = Result<ConformanceReport, ConformanceFailure>;

/// A suite run, whole (`None`) or of one property.
type Runner<'a> = &'a dyn Fn(Option<Check>) -> Run;

fn policy_runs(d: Option<PolicyDefect>, only: Option<Check>) -> Run {
    let opts = options();
    let make = || broken::policy(d, &opts);
    match only {
        None => check_policy_with(&make, &opts),
        Some(p) => check_policy_only(&make, &opts, p),
    }
}

fn environment_runs(d: Option<EnvironmentDefect>, only: Option<Check>) -> Run {
    let opts = options();
    let make = || broken::environment(d);
    match only {
        None => check_environment_with(&make, &opts),
        Some(p) => check_environment_only(&make, &opts, p),
    }
}

fn workload_runs(d: Option<WorkloadDefect>, only: Option<Check>) -> Run {
    let opts = options();
    let make = || broken::workload_model(d);
    match only {
        None => check_workload_model_built_with(&make, &opts),
        Some(p) => check_workload_model_built_only(&make, &opts, p),
    }
}

fn channel_runs(d: Option<ChannelDefect>, only: Option<Check>) -> Run {
    let opts = options();
    let make = || broken::query_channel(d);
    match only {
        None => check_query_channel_with(&make, &opts),
        Some(p) => check_query_channel_only(&make, &opts, p),
    }
}

/// The suite, and the broken property alone, fail with the defect's check.
fn assert_caught(what: &str, breaks: Check, run: impl Fn(Option<Check>) -> Run) {
    let e = run(None).expect_err(what);
    assert_eq!(
        e.check, breaks,
        "{what}: the whole suite failed another check: {e}"
    );
    if !breaks.is_prerequisite() {
        let e = run(Some(breaks)).expect_err(what);
        assert_eq!(
            e.check, breaks,
            "{what}: the property alone failed another check: {e}"
        );
    }
}

#[test]
fn every_broken_policy_fails_its_check() {
    for &d in PolicyDefect::ALL {
        assert_caught(&format!("{d:?}"), d.breaks(), |only| {
            policy_runs(Some(d), only)
        });
    }
}

#[test]
fn every_broken_environment_fails_its_check() {
    for &d in EnvironmentDefect::ALL {
        assert_caught(&format!("{d:?}"), d.breaks(), |only| {
            environment_runs(Some(d), only)
        });
    }
}

#[test]
fn every_broken_workload_model_fails_its_check() {
    for &d in WorkloadDefect::ALL {
        assert_caught(&format!("{d:?}"), d.breaks(), |only| {
            workload_runs(Some(d), only)
        });
    }
}

#[test]
fn every_broken_channel_fails_its_check() {
    for &d in ChannelDefect::ALL {
        assert_caught(&format!("{d:?}"), d.breaks(), |only| {
            channel_runs(Some(d), only)
        });
    }
}

#[test]
fn every_check_has_a_broken_implementation() {
    let covered: HashSet<Check> = PolicyDefect::ALL
        .iter()
        .map(|d| d.breaks())
        .chain(EnvironmentDefect::ALL.iter().map(|d| d.breaks()))
        .chain(WorkloadDefect::ALL.iter().map(|d| d.breaks()))
        .chain(ChannelDefect::ALL.iter().map(|d| d.breaks()))
        .collect();
    let missing: Vec<&Check> = Check::ALL.iter().filter(|c| !covered.contains(c)).collect();
    assert!(
        missing.is_empty(),
        "checks without a broken implementation: {missing:?}"
    );
}

#[test]
fn the_unbroken_implementations_pass_every_property() {
    let subjects: [(Subject, Runner<'_>); 4] = [
        (Subject::Policy, &|only| policy_runs(None, only)),
        (Subject::Environment, &|only| environment_runs(None, only)),
        (Subject::WorkloadModel, &|only| workload_runs(None, only)),
        (Subject::QueryChannel, &|only| channel_runs(None, only)),
    ];
    for (subject, run) in subjects {
        let report = run(None).unwrap_or_else(|e| panic!("{subject:?}: {e}"));
        assert!(
            report.skipped.is_empty(),
            "{subject:?}: {:?}",
            report.skipped
        );
        for p in Check::properties(subject) {
            assert!(report.passed.contains(&p), "{subject:?}: {p} not exercised");
            assert_conforms(run(Some(p)), p);
        }
    }
}

#[test]
fn a_guarded_panic_is_a_failure_never_a_refusal() {
    let opts = options();
    // Through the guard, a longer context is a HilError::Plugin ...
    let mut p = broken::policy(Some(PolicyDefect::PanicsOnLongerContext), &opts).unwrap();
    let x = hil_core::Context::new(vec![0.0; 5]).unwrap();
    let history = hil_core::QueryHistory::new();
    let input = hil_core::DecisionInput::new(
        &x,
        1,
        hil_core::WorkloadForecast::new(Some(opts.workload()), 0.5, &history, 1),
    );
    assert!(matches!(p.decide(&input), Err(HilError::Plugin { .. })));
    // ... which the suite does not count as rejecting the wrong dimension.
    let e = policy_runs(Some(PolicyDefect::PanicsOnLongerContext), None).unwrap_err();
    assert_eq!(e.check, Check::RejectsWrongDimension);
    // A panicking save is a checkpoint failure, not "skipped".
    let e = policy_runs(Some(PolicyDefect::PanicsInSave), None).unwrap_err();
    assert_eq!(e.check, Check::Checkpoint);
}

#[test]
fn a_component_failing_on_its_50th_call_fails_only_a_long_trajectory() {
    // With the old 40-step trajectory each passes; the default (300) fails it.
    let short = options().with_steps(40);
    let p = || broken::policy(Some(PolicyDefect::FailsOnCall50), &short);
    check_policy_with(&p, &short).unwrap();
    let e = policy_runs(Some(PolicyDefect::FailsOnCall50), None).unwrap_err();
    assert_eq!(e.check, Check::PolicyDecides);

    let env = || broken::environment(Some(EnvironmentDefect::FailsOnCall50));
    check_environment_with(&env, &short).unwrap();
    let ch = || broken::query_channel(Some(ChannelDefect::FailsOnCall50));
    check_query_channel_with(&ch, &short).unwrap();
    let m = broken::workload_model(Some(WorkloadDefect::FailsAfter50Queries)).unwrap();
    check_workload_model_with(m.as_ref(), &short).unwrap();
    let e = check_workload_model_with(m.as_ref(), &options()).unwrap_err();
    assert_eq!(e.check, Check::Predicts);
}

#[test]
fn a_panic_gets_the_hint_of_the_method_that_panicked() {
    // seed cannot fail: its panic poisons the policy, and the hint is about
    // seed, not about validating decide's input.
    let e = policy_runs(Some(PolicyDefect::PanicsInSeed), None).unwrap_err();
    assert_eq!(e.check, Check::PolicyDecides);
    assert_eq!(e.panicked_in.as_deref(), Some("seed"));
    assert_ne!(e.hint(), Check::PolicyDecides.hint());
    // A Drop panicking inside restore: not "save() misses part of the state".
    let e = policy_runs(Some(PolicyDefect::DropPanicsInRestore), None).unwrap_err();
    assert_eq!(e.check, Check::Checkpoint);
    assert_eq!(e.panicked_in.as_deref(), Some("restore"));
    assert_ne!(e.hint(), Check::Checkpoint.hint());
    // A checkpoint that merely forgets state keeps the checkpoint hint.
    let e = policy_runs(Some(PolicyDefect::CheckpointForgetsRng), None).unwrap_err();
    assert_eq!(
        (e.panicked_in.clone(), e.hint()),
        (None, Check::Checkpoint.hint().to_string())
    );
}

#[test]
fn destructor_panics_fail_once_per_report_in_every_suite() {
    let failures = [
        policy_runs(Some(PolicyDefect::PanicsInDrop), None),
        environment_runs(Some(EnvironmentDefect::PanicsInDrop), None),
        workload_runs(Some(WorkloadDefect::PanicsInDrop), None),
        channel_runs(Some(ChannelDefect::PanicsInDrop), None),
    ];
    for r in failures {
        let e = r.unwrap_err();
        assert_eq!(
            (e.check, e.panicked_in.as_deref()),
            (Check::Destructor, Some("drop"))
        );
    }
    // Nothing is left over for the next suite on this thread.
    assert!(hil_plugin::take_destructor_panics_on_this_thread().is_empty());
    // The borrowed form cannot drop the model: it does not claim the check.
    let m = broken::workload_model(Some(WorkloadDefect::PanicsInDrop)).unwrap();
    let report = check_workload_model_with(m.as_ref(), &options()).unwrap();
    assert!(!report.passed.contains(&Check::Destructor));
    drop(m);
    assert_eq!(hil_plugin::take_destructor_panics_on_this_thread().len(), 1);
}

#[test]
fn a_channel_assuming_six_actions_passes_only_over_six() {
    let six = CheckOptions::default();
    let make = || broken::query_channel(Some(ChannelDefect::AssumesSixActions));
    check_query_channel_with(&make, &six).unwrap();
    let e = check_query_channel_with(&make, &options()).unwrap_err();
    assert_eq!(e.check, Check::ExpertArmInRange);
}

#[test]
fn a_generated_test_fails_naming_its_property() {
    let r = policy_runs(
        Some(PolicyDefect::PanicsOnLongerContext),
        Some(Check::RejectsWrongDimension),
    );
    let panic = std::panic::catch_unwind(|| assert_conforms(r, Check::RejectsWrongDimension))
        .expect_err("the property fails");
    let message = panic.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(
        message.starts_with("property `rejects wrong dimension` does not hold for `broken_policy`"),
        "{message}"
    );
    // The policy's other properties still hold.
    for p in [Check::Determinism, Check::Checkpoint, Check::ArmInRange] {
        assert_conforms(
            policy_runs(Some(PolicyDefect::PanicsOnLongerContext), Some(p)),
            p,
        );
    }
}

// The generated tests themselves, for the conforming implementations.
hil_conformance::conformance_tests! {
    policy generated_policy {
        options: options(),
        make: |opts| broken::policy(None, opts),
    }
}
hil_conformance::conformance_tests! {
    environment generated_environment {
        options: options(),
        make: |_opts| broken::environment(None),
    }
}
hil_conformance::conformance_tests! {
    workload_model generated_workload_model {
        options: options(),
        make: |_opts| broken::workload_model(None),
    }
}
hil_conformance::conformance_tests! {
    query_channel generated_query_channel {
        options: options(),
        make: |_opts| broken::query_channel(None),
    }
}

#[test]
fn options_outside_their_limits_are_a_build_failure_naming_the_option() {
    let build = |r: Run, name: &str| {
        let e = r.expect_err(name);
        assert_eq!(e.check, Check::Build, "{e}");
        assert!(e.detail.contains(name), "{e}");
    };
    // Zero was silently read as one; a 20-digit count ran for ever.
    let ch = || broken::query_channel(None);
    for n in [0, usize::MAX] {
        build(
            check_query_channel_with(&ch, &options().with_queries(n)),
            "queries",
        );
    }
    let mut one = broken::query_channel(None).unwrap();
    build(
        hil_conformance::check_query_channel(one.as_mut(), 0),
        "queries",
    );
    let env = || broken::environment(None);
    build(hil_conformance::check_environment(&env, 0), "attempts");
    build(hil_conformance::check_environment(&env, 1001), "attempts");
    let opts = options().with_context_dim(usize::MAX);
    let p = || broken::policy(None, &opts);
    build(check_policy_with(&p, &opts), "context_dim");
}
