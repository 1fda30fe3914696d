//! The session loop checks what components return, with errors naming the
//! component and the field: deliberately broken components, run with and
//! without an interaction log.

use std::path::PathBuf;
use std::sync::Arc;

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::channel::PerfectExpert;
use hil_core::{
    ActionSpace, ArmId, Choice, Decision, DecisionInput, Diagnostics, Feedback, HilError, Policy,
    Query, QueryChannel, QueryKind, Response, SessionSettings, WorkloadModel,
};
use hil_experiments::Experiment;
use hil_experiments::run_recorded;
use hil_record::{Header, RecordLog};

/// Decides like `ScriptedPolicy` but reports a NaN gap.
struct NanDiagnostics(ScriptedPolicy);

impl Policy for NanDiagnostics {
    fn name(&self) -> &str {
        "nan_diagnostics"
    }
    fn n_arms(&self) -> usize {
        self.0.n_arms()
    }
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> hil_core::Result<Decision> {
        let d = self.0.decide(input)?;
        Ok(d.with_diagnostics(Diagnostics::new().with_gap(f64::NAN)))
    }
    fn observe(&mut self, feedback: &Feedback<'_>) -> hil_core::Result<()> {
        self.0.observe(feedback)
    }
}

/// A workload model that predicts 2.83 once a query was asked.
struct OutOfRange;

impl WorkloadModel for OutOfRange {
    fn name(&self) -> &str {
        "out_of_range"
    }
    fn predict(&self, input: &hil_core::WorkloadInput<'_>) -> hil_core::Result<f64> {
        Ok(if input.history.is_empty() {
            input.wl0
        } else {
            2.83
        })
    }
}

/// An expert whose answers take forever.
struct Eternal;

impl QueryChannel for Eternal {
    fn name(&self) -> &str {
        "eternal"
    }
    fn ask(&mut self, q: &Query) -> hil_core::Result<Response> {
        let mut r = PerfectExpert::default().ask(q)?;
        r.response_time_s = Some(f64::INFINITY);
        Ok(r)
    }
}

fn query_then_act() -> ScriptedPolicy {
    let q = Choice::Query {
        kind: QueryKind::default(),
        fallback: ArmId(0),
    };
    ScriptedPolicy::new(2, 4, vec![q, Choice::Act { arm: ArmId(1) }])
}

fn experiment() -> Experiment {
    let env = TableEnv::new(
        ActionSpace::new(["A", "B"]).unwrap(),
        vec![("kiwi", vec![0.2, 0.7]), ("pea", vec![0.5, 0.1])],
    )
    .unwrap();
    Experiment {
        settings: SessionSettings::default(),
        seed: 3,
        episodes: 1,
        environment: Box::new(env),
        policy: Box::new(query_then_act()),
        channel: Box::new(PerfectExpert::default()),
        workload: Arc::new(CountingWorkload::new(0.1)),
        forecast: None,
    }
}

fn log_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hil-session-checks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{name}.jsonl"));
    let _ = std::fs::remove_file(&p);
    p
}

/// Runs `exp` without a log, then with one; both must fail with an
/// `InvalidInput` whose `what` is `expected`, and the log must stay
/// resumable up to the failure.
fn assert_refused(make: impl Fn() -> Experiment, expected: &str, name: &str) {
    let check = |e: HilError| match e {
        HilError::InvalidInput { what, why } => {
            assert_eq!(what, expected, "{why}");
            assert!(why.len() < 200, "a short message, not a dump: {why}");
        }
        other => panic!("expected an invalid-input error, got {other:?}"),
    };
    check(make().run(&mut [], |_, _| {}).unwrap_err());
    let path = log_path(name);
    let log = RecordLog::create(&path, Header::new("seed = 3", "x.toml", ".", 3, 1)).unwrap();
    check(run_recorded(&mut make(), log, None, &mut [], |_, _| {}).unwrap_err());
    RecordLog::open(&path).expect("what was logged before the refusal reads back");
}

#[test]
fn non_finite_diagnostics_are_refused_naming_the_policy_and_field() {
    assert_refused(
        || Experiment {
            policy: Box::new(NanDiagnostics(query_then_act())),
            ..experiment()
        },
        "`diagnostics.gap` of policy `nan_diagnostics`",
        "nan",
    );
}

#[test]
fn workload_outside_the_unit_interval_is_refused_naming_the_model() {
    assert_refused(
        || Experiment {
            workload: Arc::new(OutOfRange),
            ..experiment()
        },
        "`predict` of workload model `out_of_range`",
        "wl",
    );
    // The same for the model a policy forecasts with.
    assert_refused(
        || Experiment {
            forecast: Some(Arc::new(OutOfRange)),
            policy: Box::new(ForecastingPolicy),
            ..experiment()
        },
        "`predict_if_queried` of workload model `out_of_range`",
        "forecast",
    );
}

/// Asks its workload forecast before every decision, then acts.
struct ForecastingPolicy;

impl Policy for ForecastingPolicy {
    fn name(&self) -> &str {
        "forecasting"
    }
    fn n_arms(&self) -> usize {
        2
    }
    fn dim(&self) -> usize {
        4 // two item types + 2 (TableEnv)
    }
    fn decide(&mut self, input: &DecisionInput<'_>) -> hil_core::Result<Decision> {
        input.workload.if_queried(QueryKind::default())?;
        Ok(Decision::act(ArmId(0)))
    }
    fn observe(&mut self, _feedback: &Feedback<'_>) -> hil_core::Result<()> {
        Ok(())
    }
}

#[test]
fn infinite_response_times_are_refused_naming_the_channel() {
    assert_refused(
        || Experiment {
            channel: Box::new(Eternal),
            ..experiment()
        },
        "`response_time_s` of query channel `eternal`",
        "rt",
    );
}
