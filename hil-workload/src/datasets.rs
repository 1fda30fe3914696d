//! Training datasets D1, D2 and D12 built from a [`Study`].
//!
//! One training pair per query row: the target is that survey's workload
//! score; the history holds the queries of the same condition up to and
//! including it, on the Δt = 10 s grid.
//!
//! **Time.** `query_time_s` runs on the task clock (survey time excluded).
//! Survey time is added back: the effective time of a query is its task time
//! plus the survey durations of the earlier surveys in that condition, with
//! the paper's assumption per dataset:
//! - D1: every survey takes 0 s;
//! - D2 and D12: people without limitations take 5 s, as does anyone whose
//!   time was not logged; the logged time otherwise.
//!
//! The timestep of a query is `floor(effective_time / 10 s)`.
//!
//! **WL_0 (a documented choice; the paper does not say).** The initial
//! workload of every pair is the participant's mean workload over their
//! surveys without a query (the baseline conditions: distraction only). It
//! measures the person's resting workload before any robot query. A
//! participant with query rows but no baseline survey is an error.

use std::collections::BTreeMap;
use std::sync::Arc;

use hil_core::{HilError, QueryHistory, QueryRecord, Result, TimeGrid, Timestep};
use serde::{Deserialize, Serialize};

use crate::study::{Population, Study, StudyRecord};

/// Which participants a dataset holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DatasetId {
    /// Participants without mobility limitations.
    D1,
    /// Participants with mobility limitations and occupational therapists.
    D2,
    /// Both.
    D12,
}

impl DatasetId {
    /// All three, in table order.
    pub const ALL: [Self; 3] = [Self::D1, Self::D2, Self::D12];

    /// Lower-case name (`d1`, `d2`, `d12`).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::D1 => "d1",
            Self::D2 => "d2",
            Self::D12 => "d12",
        }
    }

    /// Parses `d1`, `d2` or `d12` (case-insensitive).
    pub fn parse(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "d1" => Ok(Self::D1),
            "d2" => Ok(Self::D2),
            "d12" | "d1,2" | "d1_2" => Ok(Self::D12),
            _ => Err(HilError::invalid_parameter(
                "population",
                s,
                "expected d1, d2 or d12",
            )),
        }
    }

    /// Whether a participant of `pop` belongs to this dataset.
    pub fn includes(self, pop: Population) -> bool {
        match self {
            Self::D1 => !pop.is_limited(),
            Self::D2 => pop.is_limited(),
            Self::D12 => true,
        }
    }

    /// The survey duration assumed for `r` under this dataset's rule.
    pub fn survey_seconds(self, r: &StudyRecord) -> f64 {
        match self {
            Self::D1 => 0.0,
            Self::D2 | Self::D12 => {
                if r.population.is_limited() {
                    r.survey_time_s.unwrap_or(5.0)
                } else {
                    5.0
                }
            }
        }
    }
}

/// The queries of one condition up to and including one of them: a prefix
/// of the condition's history, which every pair of the condition shares.
///
/// Sharing keeps a dataset linear in the study's rows: a condition with n
/// queries holds its history once (n records) instead of once per pair
/// (n²/2 records; 3 GB for a 20,000-query condition).
///
/// ```
/// use std::sync::Arc;
/// use hil_core::{QueryHistory, QueryKind};
/// use hil_workload::datasets::HistoryPrefix;
/// let mut all = QueryHistory::new();
/// for t in [2, 5, 9] {
///     all.push(t, QueryKind::default()).unwrap();
/// }
/// let all = Arc::new(all);
/// let first_two = HistoryPrefix::new(Arc::clone(&all), 2);
/// assert_eq!(first_two.len(), 2);
/// assert_eq!(first_two.records().last().unwrap().t, 5);
/// assert_eq!(first_two.to_history().len(), 2);
/// // Only the prefix counts: the first query alone, from either history.
/// let mut one = QueryHistory::new();
/// one.push(2, QueryKind::default()).unwrap();
/// assert_eq!(HistoryPrefix::new(all, 1), HistoryPrefix::new(Arc::new(one), 1));
/// ```
#[derive(Clone)]
pub struct HistoryPrefix {
    all: Arc<QueryHistory>,
    len: usize,
}

// Equality and debug output are those of the prefix's queries: what the
// rest of the shared history holds is not part of the value.
impl PartialEq for HistoryPrefix {
    fn eq(&self, other: &Self) -> bool {
        self.records() == other.records()
    }
}

impl std::fmt::Debug for HistoryPrefix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.records()).finish()
    }
}

impl HistoryPrefix {
    /// The first `len` queries of `all` (at most all of them).
    pub fn new(all: Arc<QueryHistory>, len: usize) -> Self {
        let len = len.min(all.len());
        Self { all, len }
    }

    /// The queries of the prefix, oldest first.
    pub fn records(&self) -> &[QueryRecord] {
        &self.all.records()[..self.len]
    }

    /// The whole history this is a prefix of (one per condition, shared by
    /// its pairs): pairs with the same one can be walked in one pass.
    pub fn whole(&self) -> &Arc<QueryHistory> {
        &self.all
    }

    /// Number of queries in the prefix.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if the prefix holds no query.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The prefix as an owned [`QueryHistory`], for [`hil_core::WorkloadModel`]
    /// calls. It copies the prefix (O(len)): call it per prediction, do not
    /// store the result.
    pub fn to_history(&self) -> QueryHistory {
        QueryHistory::from_records(self.records().to_vec())
            .expect("a prefix of a valid history is valid")
    }
}

/// The indices of `pairs` grouped by the whole history their prefixes share
/// (one group per condition), each group ordered by prefix length: walking
/// a group front to back visits its history's queries once, so work that
/// is carried forward along a condition costs O(pairs + queries), not
/// O(pairs × queries).
pub(crate) fn by_shared_history(pairs: &[&TrainingPair]) -> Vec<Vec<usize>> {
    // Groups in order of first appearance (not of address), so that
    // anything summed group by group is the same on every run.
    let mut group_of: std::collections::HashMap<*const QueryHistory, usize> =
        std::collections::HashMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, p) in pairs.iter().enumerate() {
        let g = *group_of
            .entry(Arc::as_ptr(p.history.whole()))
            .or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
        groups[g].push(i);
    }
    for g in &mut groups {
        // Stable: pairs with one prefix keep their given order.
        g.sort_by_key(|&i| pairs[i].history.len());
    }
    groups
}

/// One (query history, workload) training pair.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainingPair {
    /// Index into [`Dataset::participants`].
    pub participant: usize,
    /// Initial workload (participant baseline).
    pub wl0: f64,
    /// Timestep of the query (where the workload was measured).
    pub t: Timestep,
    /// The condition's queries up to and including this one (shared with
    /// the condition's other pairs).
    pub history: HistoryPrefix,
    /// Measured workload after the query.
    pub target: f64,
}

/// A dataset of training pairs.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// Which dataset this is.
    pub id: DatasetId,
    /// Participant ids (pairs refer to them by index).
    pub participants: Vec<String>,
    /// The pairs, in study order.
    pub pairs: Vec<TrainingPair>,
}

impl Dataset {
    /// Builds dataset `id` from `study` with the default Δt = 10 s.
    ///
    /// ```
    /// use hil_workload::{datasets::{Dataset, DatasetId}, synth::SynthConfig};
    /// let study = SynthConfig::small(3, 1).generate(7).unwrap();
    /// let d1 = Dataset::build(&study, DatasetId::D1).unwrap();
    /// assert_eq!(d1.pairs.len(), 3 * 48);
    /// ```
    pub fn build(study: &Study, id: DatasetId) -> Result<Self> {
        Self::build_with_grid(study, id, TimeGrid::default())
    }

    /// Builds dataset `id` on a custom time grid.
    pub fn build_with_grid(study: &Study, id: DatasetId, grid: TimeGrid) -> Result<Self> {
        Self::build_if_any_with_grid(study, id, grid)?.ok_or_else(|| no_query_rows(study, id))
    }

    /// Builds dataset `id`, or `None` if the study has no query rows of its
    /// population (e.g. D2 of a study with only D1 participants). Every
    /// other fault in the data is an error, as with [`Dataset::build`].
    ///
    /// ```
    /// use hil_workload::{datasets::{Dataset, DatasetId}, study::Study};
    /// let header = "participant,population,condition,query_time_s,difficulty,response_type,distraction,interval_min,mental,temporal,performance,effort,frustration,survey_time_s";
    /// let base = "p1,no_limitation,base,330,,,easy,,2,1,4,2,1,";
    /// let query = "p1,no_limitation,c1,60,easy,mcq,none,1,3,2,4,3,1,";
    /// let study = Study::parse(&format!("{header}\n{base}\n{query}\n"), "s.csv".as_ref()).unwrap();
    /// assert!(Dataset::build_if_any(&study, DatasetId::D1).unwrap().is_some());
    /// assert!(Dataset::build_if_any(&study, DatasetId::D2).unwrap().is_none());
    /// // Without the baseline survey WL_0 is unknown: an error, not `None`.
    /// let study = Study::parse(&format!("{header}\n{query}\n"), "s.csv".as_ref()).unwrap();
    /// assert!(Dataset::build_if_any(&study, DatasetId::D1).is_err());
    /// ```
    pub fn build_if_any(study: &Study, id: DatasetId) -> Result<Option<Self>> {
        Self::build_if_any_with_grid(study, id, TimeGrid::default())
    }

    fn build_if_any_with_grid(
        study: &Study,
        id: DatasetId,
        grid: TimeGrid,
    ) -> Result<Option<Self>> {
        let mut participants: Vec<String> = Vec::new();
        let mut p_index: BTreeMap<&str, usize> = BTreeMap::new();
        // participant -> (sum, count) of baseline workloads
        let mut baseline: BTreeMap<usize, (f64, usize)> = BTreeMap::new();
        // (participant, condition) -> query rows, in file order
        let mut conditions: BTreeMap<(usize, &str), Vec<&StudyRecord>> = BTreeMap::new();
        let mut order: Vec<(usize, &str)> = Vec::new();
        for r in study.records().iter().filter(|r| id.includes(r.population)) {
            let p = *p_index.entry(&r.participant).or_insert_with(|| {
                participants.push(r.participant.clone());
                participants.len() - 1
            });
            match r.query {
                None => {
                    let e = baseline.entry(p).or_insert((0.0, 0));
                    e.0 += r.tlx.workload();
                    e.1 += 1;
                }
                Some(_) => {
                    let key = (p, r.condition.as_str());
                    let v = conditions.entry(key).or_default();
                    if v.is_empty() {
                        order.push(key);
                    }
                    v.push(r);
                }
            }
        }
        let mut pairs = Vec::new();
        for key in order {
            let rows = &conditions[&key];
            let p = key.0;
            let Some(&(sum, n)) = baseline.get(&p) else {
                return Err(HilError::Data {
                    path: study.source().to_path_buf(),
                    record: rows[0].line,
                    field: "participant".into(),
                    why: format!(
                        "participant `{}` has query rows but no survey without a query, so WL_0 (their baseline workload) is unknown",
                        participants[p]
                    ),
                });
            };
            let wl0 = sum / n as f64;
            let mut sorted: Vec<&StudyRecord> = rows.clone();
            sorted.sort_by(|a, b| a.query_time_s.total_cmp(&b.query_time_s));
            // The condition's history is built once; its pairs refer to
            // prefixes of it.
            let mut history = QueryHistory::new();
            let mut survey_offset = 0.0;
            for r in &sorted {
                let t = grid.step_of(r.query_time_s + survey_offset);
                let kind = r.kind().expect("query rows only");
                history.push(t, kind)?;
                survey_offset += id.survey_seconds(r);
            }
            let history = Arc::new(history);
            for (i, (r, q)) in sorted.iter().zip(history.records()).enumerate() {
                pairs.push(TrainingPair {
                    participant: p,
                    wl0,
                    t: q.t,
                    history: HistoryPrefix::new(Arc::clone(&history), i + 1),
                    target: r.tlx.workload(),
                });
            }
        }
        if pairs.is_empty() {
            return Ok(None);
        }
        Ok(Some(Self {
            id,
            participants,
            pairs,
        }))
    }

    /// Workload scores of all surveys with a query (the targets).
    pub fn targets(&self) -> Vec<f64> {
        self.pairs.iter().map(|p| p.target).collect()
    }
}

/// The error for a dataset without query rows.
pub(crate) fn no_query_rows(study: &Study, id: DatasetId) -> HilError {
    HilError::Data {
        path: study.source().to_path_buf(),
        record: 1,
        field: "population".into(),
        why: format!("dataset {} has no query rows", id.as_str().to_uppercase()),
    }
}
