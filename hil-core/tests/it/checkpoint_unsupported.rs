//! The conformance suite skips the checkpoint check exactly when `save`
//! reports [`HilError::Unsupported`] (the trait's default), and fails it
//! for any other error, [`HilError::State`] included.

use hil_conformance::fixtures::ScriptedPolicy;
use hil_conformance::{Check, check_policy};
use hil_core::{Decision, DecisionInput, Feedback, HilError, Policy, Result};

/// The scripted fixture, with `save` either the trait's default or a
/// refusal "in this state".
#[derive(Debug)]
struct NoCheckpoint {
    inner: ScriptedPolicy,
    refuse_as_state: bool,
}

impl Policy for NoCheckpoint {
    fn name(&self) -> &str {
        "no_checkpoint"
    }
    fn n_arms(&self) -> usize {
        self.inner.n_arms()
    }
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> Result<Decision> {
        self.inner.decide(input)
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> Result<()> {
        self.inner.observe(feedback)
    }
    fn save(&self) -> Result<serde_json::Value> {
        if self.refuse_as_state {
            Err(HilError::state(self.name(), "not now"))
        } else {
            Err(HilError::unsupported(self.name(), "checkpoints", "default"))
        }
    }
}

fn make(refuse_as_state: bool) -> impl Fn() -> Result<Box<dyn Policy>> {
    move || {
        Ok(Box::new(NoCheckpoint {
            inner: ScriptedPolicy::new(6, 8, Vec::new()),
            refuse_as_state,
        }) as Box<dyn Policy>)
    }
}

#[test]
fn the_default_save_is_unsupported() {
    // A policy that leaves save/restore to the trait.
    #[derive(Debug)]
    struct Defaults;
    impl Policy for Defaults {
        fn name(&self) -> &str {
            "defaults"
        }
        fn n_arms(&self) -> usize {
            1
        }
        fn dim(&self) -> usize {
            1
        }
        fn decide(&mut self, _: &DecisionInput<'_>) -> Result<Decision> {
            unreachable!("not called")
        }
        fn observe(&mut self, _: &Feedback<'_>) -> Result<()> {
            unreachable!("not called")
        }
    }
    assert!(matches!(Defaults.save(), Err(HilError::Unsupported { .. })));
    assert!(matches!(
        Defaults.restore(serde_json::Value::Null),
        Err(HilError::Unsupported { .. })
    ));
}

#[test]
fn an_unsupported_checkpoint_is_skipped() {
    let report = check_policy(&make(false)).expect("conforms");
    assert!(
        report.skipped.iter().any(|(c, _)| *c == Check::Checkpoint),
        "{report:?}"
    );
}

#[test]
fn a_state_error_from_save_fails_the_checkpoint_check() {
    let e = check_policy(&make(true)).expect_err("a refusing save is not a skip");
    assert_eq!(e.check, Check::Checkpoint);
}
