//! Checks on what components hand back to the session loop.
//!
//! A policy, workload model or channel (built in or a plugin) may return a
//! number the session cannot use: a NaN diagnostic, a workload of 2.83, an
//! infinite response time. Passed on, such a value is scored, printed, or
//! written to the log as `null` (JSON has no NaN), where it breaks resuming
//! much later. So the loop checks every value when it arrives, and the
//! error names the component and the field.

use std::sync::Arc;

use crate::decision::Diagnostics;
use crate::error::{HilError, Result};
use crate::query::{QueryKind, Response};
use crate::time::Timestep;
use crate::workload::{WorkloadInput, WorkloadModel};

/// Every diagnostic of a policy's decision must be finite. Runs at every
/// step, so it allocates only to name a bad field.
pub(crate) fn diagnostics(policy: &str, d: &Diagnostics) -> Result<()> {
    match d.first_non_finite() {
        Some((field, v)) => Err(HilError::invalid_input(
            format!("`diagnostics.{field}` of policy `{policy}`"),
            format!("{v} is not a finite number"),
        )),
        None => Ok(()),
    }
}

/// A response time, when a channel reports one, is a finite number of
/// seconds, not negative.
pub(crate) fn response(channel: &str, r: &Response) -> Result<()> {
    match r.response_time_s {
        Some(s) if !(s.is_finite() && s >= 0.0) => Err(HilError::invalid_input(
            format!("`response_time_s` of query channel `{channel}`"),
            format!("{s} is not a finite, non-negative number of seconds"),
        )),
        _ => Ok(()),
    }
}

/// A workload model whose every prediction is checked to be a workload
/// score in [0, 1]; the session tracks, forecasts and scores through it.
pub(crate) struct CheckedWorkload(pub(crate) Arc<dyn WorkloadModel>);

impl CheckedWorkload {
    fn check(&self, wl: f64, t: Timestep, what: &str) -> Result<f64> {
        if (0.0..=1.0).contains(&wl) {
            return Ok(wl);
        }
        Err(HilError::invalid_input(
            format!("`{what}` of workload model `{}`", self.0.name()),
            format!("{wl} at t = {t} is not a workload score in [0, 1]"),
        ))
    }
}

impl WorkloadModel for CheckedWorkload {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        self.check(self.0.predict(input)?, input.t, "predict")
    }

    fn predict_if_queried(&self, input: &WorkloadInput<'_>, kind: QueryKind) -> Result<f64> {
        let wl = self.0.predict_if_queried(input, kind)?;
        self.check(wl, input.t, "predict_if_queried")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decision::ArmDiagnostics;

    #[test]
    fn the_first_non_finite_diagnostic_is_named() {
        let mut d = Diagnostics {
            arms: vec![ArmDiagnostics {
                estimate: 0.1,
                bonus: 0.2,
                ucb: 0.3,
            }],
            gap: Some(0.5),
            ..Default::default()
        };
        diagnostics("p", &d).unwrap();
        d.arms[0].ucb = f64::INFINITY;
        match diagnostics("p", &d).unwrap_err() {
            HilError::InvalidInput { what, .. } => {
                assert_eq!(what, "`diagnostics.arms[0].ucb` of policy `p`")
            }
            e => panic!("{e:?}"),
        }
        d.arms[0].ucb = 0.3;
        d.query_probability = Some(f64::NAN);
        let e = diagnostics("p", &d).unwrap_err().to_string();
        assert!(e.contains("diagnostics.query_probability"), "{e}");
        d.query_probability = None;
        d.extra.insert("agreement", f64::NAN);
        match diagnostics("p", &d).unwrap_err() {
            HilError::InvalidInput { what, .. } => {
                assert_eq!(what, "`diagnostics.extra.agreement` of policy `p`")
            }
            e => panic!("{e:?}"),
        }
    }

    #[test]
    fn extras_round_trip_and_are_left_out_when_empty() {
        let d = Diagnostics::new()
            .with_gap(0.5)
            .with_extra("agreement", 0.75);
        let json = serde_json::to_string(&d).unwrap();
        assert_eq!(json, r#"{"gap":0.5,"extra":{"agreement":0.75}}"#);
        assert_eq!(serde_json::from_str::<Diagnostics>(&json).unwrap(), d);
        let plain = serde_json::to_string(&Diagnostics::new().with_gap(0.5)).unwrap();
        assert_eq!(plain, r#"{"gap":0.5}"#);
    }

    #[test]
    fn response_times_must_be_finite_and_not_negative() {
        let mut r = Response::action(crate::ArmId(0));
        response("c", &r).unwrap();
        for bad in [f64::INFINITY, f64::NAN, -1.0] {
            r.response_time_s = Some(bad);
            assert!(matches!(
                response("c", &r),
                Err(HilError::InvalidInput { .. })
            ));
        }
    }
}
