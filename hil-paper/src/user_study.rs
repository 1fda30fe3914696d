//! The real-robot user study (Sec. V-C and the appendix): its protocol and
//! its published objective table.

use crate::MeanSd;
use crate::methods::PaperMethod;

/// Attempts per item (N_att) in the study.
pub const N_ATT: u32 = 3;
/// The fixed WL_0 LinUCB-QG is given in the study.
pub const WL0: f64 = 0.5;
/// The foods of every plate.
pub const PLATE: [&str; 3] = ["banana", "carrot", "cantaloupe"];
/// Repetitions of the plate per method.
pub const REPETITIONS: usize = 2;

/// One row of the study's objective table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudyRow {
    /// The method.
    pub method: PaperMethod,
    /// r_task_avg.
    pub r_task_avg: MeanSd,
    /// Items fed per plate.
    pub n_success: MeanSd,
    /// Queries per plate (`None` where the table prints "-": LinUCB never
    /// asks, so it is 0).
    pub n_q: Option<MeanSd>,
}

impl StudyRow {
    /// Queries per plate, 0 where the table prints "-".
    pub fn n_q_mean(&self) -> f64 {
        self.n_q.map_or(0.0, |q| q.mean)
    }
}

/// The published objective table, one row per method the study ran.
pub const OBJECTIVE: [StudyRow; 3] = [
    StudyRow {
        method: PaperMethod::LinUcb,
        r_task_avg: MeanSd::new(0.38, 0.08),
        n_success: MeanSd::new(2.00, 0.23),
        n_q: None,
    },
    StudyRow {
        method: PaperMethod::AlwaysQuery,
        r_task_avg: MeanSd::new(0.87, 0.25),
        n_success: MeanSd::new(2.68, 0.61),
        n_q: Some(MeanSd::new(3.0, 0.0)),
    },
    StudyRow {
        method: PaperMethod::LinUcbQg,
        r_task_avg: MeanSd::new(0.68, 0.29),
        n_success: MeanSd::new(2.53, 0.72),
        n_q: Some(MeanSd::new(1.74, 0.78)),
    },
];

/// The published row of `method`, if the study ran it.
///
/// ```
/// use hil_paper::methods::PaperMethod;
/// let qg = hil_paper::user_study::row(PaperMethod::LinUcbQg).unwrap();
/// assert_eq!(qg.n_q_mean(), 1.74);
/// assert!(hil_paper::user_study::row(PaperMethod::LinUcbExpDecay).is_none());
/// ```
pub fn row(method: PaperMethod) -> Option<&'static StudyRow> {
    OBJECTIVE.iter().find(|r| r.method == method)
}
