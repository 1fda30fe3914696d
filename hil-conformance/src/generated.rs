//! [`crate::conformance_tests!`]: one `#[test]` per property.

use super::{Check, ConformanceFailure, ConformanceReport};

/// Panics, naming `property`, unless `result` (a run of that property
/// alone) passed or legitimately skipped it. The body of every test that
/// [`crate::conformance_tests!`] generates.
///
/// ```
/// use hil_conformance::{assert_conforms, check_workload_model_only, Check, CheckOptions};
/// use hil_conformance::fixtures::CountingWorkload;
/// let r = check_workload_model_only(&CountingWorkload::new(0.1), &CheckOptions::default(), Check::Counterfactual);
/// assert_conforms(r, Check::Counterfactual);
/// ```
#[track_caller]
pub fn assert_conforms(result: Result<ConformanceReport, ConformanceFailure>, property: Check) {
    match result {
        Err(f) => panic!(
            "property `{property}` does not hold for `{}`: {f}",
            f.subject
        ),
        Ok(report) => {
            if let Some((_, why)) = report.skipped.iter().find(|(c, _)| *c == property) {
                eprintln!(
                    "property `{property}` skipped for `{}`: {why}",
                    report.subject
                );
            } else if !report.passed.contains(&property) {
                panic!(
                    "property `{property}` was never exercised for `{}` (passed: {})",
                    report.subject,
                    report.passed_names()
                );
            }
        }
    }
}

/// Expands into a module of `#[test]`s, one per conformance property of a
/// trait, for the type a factory builds, so a failing test names the
/// property (`my_policy::rejects_wrong_dimension`) instead of one
/// `conforms` test failing somewhere.
///
/// `make` is a closure from the [`CheckOptions`](crate::CheckOptions)
/// to the object (`Result<Box<dyn Trait>>`); build from
/// `opts.task_context()` (policies, query channels) or
/// `opts.build_context()` (environments, workload models) as the host would. The kinds are `policy`,
/// `environment`, `workload_model` and `query_channel`. Each module also
/// has a test that its list of properties is the suite's.
///
/// ```
/// # // (doc tests do not run #[test]s; this shows the form)
/// use hil_conformance::CheckOptions;
/// use hil_conformance::fixtures::CountingWorkload;
///
/// hil_conformance::conformance_tests! {
///     workload_model counting_workload {
///         options: CheckOptions::default(),
///         make: |_opts| Ok(Box::new(CountingWorkload::new(0.1))),
///     }
/// }
/// # fn main() {}
/// ```
#[macro_export]
macro_rules! conformance_tests {
    (policy $name:ident { options: $opts:expr, make: $make:expr $(,)? }) => {
        $crate::__conformance_tests!(@factory $name, $opts, $make, Policy, check_policy_only, Policy, [
            shape => PolicyShape,
            arm_in_range => ArmInRange,
            finite_diagnostics => FiniteDiagnostics,
            diagnostics_cover_every_arm => DiagnosticsCoverArms,
            determinism => Determinism,
            rejects_wrong_dimension => RejectsWrongDimension,
            rejects_arm_out_of_range => RejectsArmOutOfRange,
            rejection_has_no_effect => RejectionHasNoEffect,
            checkpoint => Checkpoint,
            drop_does_not_panic => Destructor,
        ]);
    };
    (environment $name:ident { options: $opts:expr, make: $make:expr $(,)? }) => {
        $crate::__conformance_tests!(@factory $name, $opts, $make, Environment, check_environment_only, Environment, [
            shape => EnvironmentShape,
            episode_has_items => EpisodeHasItems,
            episodes_end => EpisodesEnd,
            current_item => CurrentItem,
            context_dimension => ContextDimension,
            success_probability => SuccessProbability,
            best_action_in_range => BestActionInRange,
            replayable => Replayable,
            execute_rejects_arm_out_of_range => ExecuteRejectsArmOutOfRange,
            out_of_order_calls => OutOfOrderCalls,
            drop_does_not_panic => Destructor,
        ]);
    };
    (query_channel $name:ident { options: $opts:expr, make: $make:expr $(,)? }) => {
        $crate::__conformance_tests!(@factory $name, $opts, $make, QueryChannel, check_query_channel_only, QueryChannel, [
            expert_arm_in_range => ExpertArmInRange,
            response_time => ResponseTime,
            answer_consistent => AnswerConsistent,
            seeded_replay => SeededReplay,
            drop_does_not_panic => Destructor,
        ]);
    };
    (workload_model $name:ident { options: $opts:expr, make: $make:expr $(,)? }) => {
        $crate::__conformance_tests!(@factory $name, $opts, $make, WorkloadModel, check_workload_model_built_only, WorkloadModel, [
            empty_history => EmptyHistory,
            finite => FinitePrediction,
            deterministic => DeterministicPrediction,
            counterfactual => Counterfactual,
            drop_does_not_panic => Destructor,
        ]);
    };
}

/// The expansion of [`conformance_tests!`].
#[doc(hidden)]
#[macro_export]
macro_rules! __conformance_tests {
    (@factory $name:ident, $opts:expr, $make:expr, $trait:ident, $runner:ident, $subject:ident,
     [$($test:ident => $check:ident),* $(,)?]) => {
        #[allow(unused_imports, clippy::redundant_closure)]
        mod $name {
            use super::*;

            fn run(
                property: $crate::Check,
            ) -> ::std::result::Result<
                $crate::ConformanceReport,
                $crate::ConformanceFailure,
            > {
                let opts: $crate::CheckOptions = $opts;
                let make: &dyn Fn(
                    &$crate::CheckOptions,
                ) -> $crate::__core::Result<::std::boxed::Box<dyn $crate::__core::$trait>> = &$make;
                $crate::$runner(&|| make(&opts), &opts, property)
            }

            $crate::__conformance_tests!(@tests $subject, [$($test => $check),*]);
        }
    };
    (@tests $subject:ident, [$($test:ident => $check:ident),*]) => {
        $(
            #[test]
            fn $test() {
                $crate::assert_conforms(
                    run($crate::Check::$check),
                    $crate::Check::$check,
                );
            }
        )*

        #[test]
        fn every_property_has_a_test() {
            ::std::assert_eq!(
                ::std::vec![$($crate::Check::$check),*],
                $crate::Check::properties($crate::Subject::$subject),
            );
        }
    };
}
