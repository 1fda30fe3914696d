//! Querying workload: the [`WorkloadModel`] trait, query histories, and the
//! tracker the session loop uses.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::error::{HilError, Result};
use crate::query::QueryKind;
use crate::time::Timestep;

/// The paper's initial workload for simulations (a median value).
pub const DEFAULT_WL0: f64 = 0.5;

/// One query in a history: when it was asked and what kind it was.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct QueryRecord {
    /// Timestep at which the query was asked.
    pub t: Timestep,
    /// What was asked.
    pub kind: QueryKind,
}

/// The history Q_t of queries asked so far, in time order.
///
/// ```
/// use hil_core::{QueryHistory, QueryKind};
/// let mut h = QueryHistory::new();
/// h.push(3, QueryKind::default()).unwrap();
/// assert!(h.push(2, QueryKind::default()).is_err()); // time runs forward
/// assert_eq!(h.len(), 1);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct QueryHistory {
    records: Vec<QueryRecord>,
}

impl QueryHistory {
    /// An empty history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds a history, checking that times do not decrease.
    pub fn from_records(records: Vec<QueryRecord>) -> Result<Self> {
        let mut h = Self::new();
        for r in records {
            h.push(r.t, r.kind)?;
        }
        Ok(h)
    }

    /// Appends a query at `t`; `t` must not precede the last query.
    /// Several queries at one timestep are allowed.
    pub fn push(&mut self, t: Timestep, kind: QueryKind) -> Result<()> {
        if let Some(last) = self.records.last()
            && t < last.t
        {
            return Err(HilError::invalid_input(
                "query time",
                format!("t = {t} precedes the previous query at t = {}", last.t),
            ));
        }
        self.records.push(QueryRecord { t, kind });
        Ok(())
    }

    /// The records, oldest first.
    pub fn records(&self) -> &[QueryRecord] {
        &self.records
    }

    /// Number of queries.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// True if no query was asked.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Number of queries asked at or before `t`.
    ///
    /// ```
    /// use hil_core::{QueryHistory, QueryKind};
    /// let mut h = QueryHistory::new();
    /// h.push(2, QueryKind::default()).unwrap();
    /// h.push(5, QueryKind::default()).unwrap();
    /// assert_eq!((h.count_until(1), h.count_until(2), h.count_until(9)), (0, 1, 2));
    /// ```
    pub fn count_until(&self, t: Timestep) -> usize {
        self.records.iter().filter(|r| r.t <= t).count()
    }

    /// The time of the last query, if any.
    pub fn last_time(&self) -> Option<Timestep> {
        self.records.last().map(|r| r.t)
    }

    /// The queries asked in `(t - window, t]`, newest first, with their lag
    /// `t - t_query`. Granger-style models read features from this.
    pub fn recent(&self, t: Timestep, window: u64) -> impl Iterator<Item = (u64, &QueryRecord)> {
        self.records
            .iter()
            .rev()
            .filter(move |r| r.t <= t)
            .map(move |r| (t - r.t, r))
            .take_while(move |(lag, _)| *lag < window)
    }
}

/// What a workload model is asked: the initial workload, the queries asked
/// so far and the timestep to predict at.
///
/// A struct rather than positional arguments, so that a later covariate
/// (time of day, the person's own rating) is a new field with a default, not
/// a change to every model's signature. Build it with [`WorkloadInput::new`].
///
/// ```
/// use hil_core::{QueryHistory, WorkloadInput};
/// let h = QueryHistory::new();
/// let input = WorkloadInput::new(0.5, &h, 3);
/// assert_eq!((input.wl0, input.t, input.history.len()), (0.5, 3, 0));
/// ```
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct WorkloadInput<'a> {
    /// The initial workload WL_0, in [0, 1].
    pub wl0: f64,
    /// The queries asked so far; queries later than `t` are ignored.
    pub history: &'a QueryHistory,
    /// The timestep to predict at.
    pub t: Timestep,
}

impl<'a> WorkloadInput<'a> {
    /// The input for WL_t given WL_0 and the queries in `history`.
    pub fn new(wl0: f64, history: &'a QueryHistory, t: Timestep) -> Self {
        Self { wl0, history, t }
    }

    /// The same question about another history (e.g. a counterfactual one).
    pub fn with_history<'b>(&self, history: &'b QueryHistory) -> WorkloadInput<'b> {
        WorkloadInput {
            wl0: self.wl0,
            history,
            t: self.t,
        }
    }
}

/// A model of querying workload: WL_t = f(WL_0, Q_t).
///
/// Contract (checked by `hil_conformance::check_workload_model`):
/// - predictions are finite for every WL_0 in [0, 1] and every history;
/// - predictions are deterministic;
/// - `predict_if_queried` equals `predict` on the history with the query appended.
pub trait WorkloadModel: Send + Sync {
    /// Short name for logs.
    fn name(&self) -> &str;

    /// Predicts WL_t from the initial workload and the queries asked up to
    /// `input.t`.
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64>;

    /// The counterfactual WL_t if a query of `kind` were asked now, at `input.t`.
    fn predict_if_queried(&self, input: &WorkloadInput<'_>, kind: QueryKind) -> Result<f64> {
        let mut h = input.history.clone();
        h.push(input.t, kind)?;
        self.predict(&input.with_history(&h))
    }
}

/// Checks that `wl0` is a workload score in [0, 1].
pub fn check_wl0(wl0: f64) -> Result<()> {
    if (0.0..=1.0).contains(&wl0) {
        Ok(())
    } else {
        Err(HilError::invalid_parameter(
            "wl0",
            wl0,
            "initial workload must be in [0, 1]",
        ))
    }
}

/// What a policy may ask about workload when it decides.
#[derive(Clone, Copy)]
pub struct WorkloadForecast<'a> {
    model: Option<&'a dyn WorkloadModel>,
    wl0: f64,
    history: &'a QueryHistory,
    t: Timestep,
}

impl std::fmt::Debug for WorkloadForecast<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorkloadForecast")
            .field("model", &self.model.map(|m| m.name().to_string()))
            .field("wl0", &self.wl0)
            .field("queries", &self.history.len())
            .field("t", &self.t)
            .finish()
    }
}

impl<'a> WorkloadForecast<'a> {
    /// A forecast backed by `model` (or none).
    pub fn new(
        model: Option<&'a dyn WorkloadModel>,
        wl0: f64,
        history: &'a QueryHistory,
        t: Timestep,
    ) -> Self {
        Self {
            model,
            wl0,
            history,
            t,
        }
    }

    /// A forecast with no model: asking it for a prediction is an error.
    pub fn none(history: &'a QueryHistory) -> Self {
        Self::new(None, DEFAULT_WL0, history, 0)
    }

    /// The initial workload.
    pub fn wl0(&self) -> f64 {
        self.wl0
    }

    /// The queries asked so far.
    pub fn history(&self) -> &QueryHistory {
        self.history
    }

    /// The predicted WL_t if a query of `kind` were asked now; a
    /// non-finite prediction is an error naming the model.
    pub fn if_queried(&self, kind: QueryKind) -> Result<f64> {
        let model = self.model()?;
        let wl =
            model.predict_if_queried(&WorkloadInput::new(self.wl0, self.history, self.t), kind)?;
        finite_prediction(model, wl, self.t)
    }

    /// The predicted WL_t without a query now; a non-finite prediction is
    /// an error naming the model.
    pub fn now(&self) -> Result<f64> {
        let model = self.model()?;
        let wl = model.predict(&WorkloadInput::new(self.wl0, self.history, self.t))?;
        finite_prediction(model, wl, self.t)
    }

    fn model(&self) -> Result<&'a dyn WorkloadModel> {
        self.model.ok_or_else(|| {
            HilError::state(
                "workload forecast",
                "no workload model is configured for this policy",
            )
        })
    }
}

/// The paper's WL_t = f(WL_0, Q_t): `model`'s prediction at timestep `t` over
/// the queries asked up to `t`, with WL_0 itself at t = 0 (before the first
/// step). The one definition the session's per-step trace, the episode
/// metrics (WL_T at the last step) and every plotted workload curve use.
///
/// ```
/// use hil_core::workload::workload_at;
/// use hil_core::{QueryHistory, QueryKind};
/// use hil_conformance::fixtures::CountingWorkload;
/// let mut q = QueryHistory::new();
/// q.push(3, QueryKind::default()).unwrap();
/// let m = CountingWorkload::new(0.1);
/// assert_eq!(workload_at(&m, 0.5, &q, 0).unwrap(), 0.5);
/// assert!((workload_at(&m, 0.5, &q, 9).unwrap() - 0.6).abs() < 1e-12);
/// ```
pub fn workload_at(
    model: &dyn WorkloadModel,
    wl0: f64,
    history: &QueryHistory,
    t: Timestep,
) -> Result<f64> {
    if t == 0 {
        return Ok(wl0);
    }
    let wl = model.predict(&WorkloadInput::new(wl0, history, t))?;
    finite_prediction(model, wl, t)
}

/// `wl`, `model`'s prediction at `t`, if finite: a NaN must never reach a
/// threshold comparison (where it would silently mean "do not ask").
fn finite_prediction(model: &dyn WorkloadModel, wl: f64, t: Timestep) -> Result<f64> {
    if wl.is_finite() {
        return Ok(wl);
    }
    Err(HilError::invalid_input(
        format!("workload prediction of `{}`", model.name()),
        format!("{wl} is not finite at t = {t}"),
    ))
}

/// Tracks the workload of one person through a session: the queries asked
/// so far and WL_t = f(WL_0, Q_t) ([`workload_at`]) at the current step, so
/// a model whose workload decays between queries decays here too.
///
/// ```
/// use std::sync::Arc;
/// use hil_core::{WorkloadTracker, QueryKind, WorkloadModel, WorkloadInput};
/// # struct PerQuery;
/// # impl WorkloadModel for PerQuery {
/// #     fn name(&self) -> &str { "per_query" }
/// #     fn predict(&self, x: &WorkloadInput<'_>) -> hil_core::Result<f64> {
/// #         Ok((x.wl0 + 0.1 * x.history.len() as f64).min(1.0))
/// #     }
/// # }
/// let mut tr = WorkloadTracker::new(Arc::new(PerQuery), 0.5).unwrap();
/// assert_eq!(tr.current(), 0.5);
/// tr.record(4, QueryKind::default()).unwrap();
/// assert!((tr.advance(4).unwrap() - 0.6).abs() < 1e-12);
/// assert!((tr.current() - 0.6).abs() < 1e-12);
/// ```
#[derive(Clone)]
pub struct WorkloadTracker {
    model: Arc<dyn WorkloadModel>,
    wl0: f64,
    history: QueryHistory,
    current: f64,
}

impl std::fmt::Debug for WorkloadTracker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorkloadTracker")
            .field("model", &self.model.name())
            .field("wl0", &self.wl0)
            .field("history", &self.history)
            .field("current", &self.current)
            .finish()
    }
}

impl WorkloadTracker {
    /// Starts tracking from `wl0` (must be in [0, 1]).
    pub fn new(model: Arc<dyn WorkloadModel>, wl0: f64) -> Result<Self> {
        check_wl0(wl0)?;
        Ok(Self {
            model,
            wl0,
            history: QueryHistory::new(),
            current: wl0,
        })
    }

    /// Records a query asked at `t` (the person was interrupted, whatever
    /// they answered). Call [`WorkloadTracker::advance`] to evaluate WL_t.
    pub fn record(&mut self, t: Timestep, kind: QueryKind) -> Result<()> {
        self.history.push(t, kind)
    }

    /// Evaluates WL_t at timestep `t` over the queries recorded so far and
    /// makes it the current workload.
    pub fn advance(&mut self, t: Timestep) -> Result<f64> {
        self.current = workload_at(self.model.as_ref(), self.wl0, &self.history, t)?;
        Ok(self.current)
    }

    /// WL_t at the last [`WorkloadTracker::advance`] (WL_0 before the first).
    pub fn current(&self) -> f64 {
        self.current
    }

    /// The initial workload WL_0.
    pub fn wl0(&self) -> f64 {
        self.wl0
    }

    /// The queries recorded so far.
    pub fn history(&self) -> &QueryHistory {
        &self.history
    }

    /// The model behind the tracker.
    pub fn model(&self) -> &dyn WorkloadModel {
        self.model.as_ref()
    }
}
