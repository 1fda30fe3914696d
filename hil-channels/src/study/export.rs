//! From the participants' event logs to the study CSV that `hil workload
//! summary / select / fit` read.
//!
//! - One row per survey after a robot query: `query_time_s` is when the
//!   query appeared on the task clock (which stops during surveys, as the
//!   format requires), `survey_time_s` the real seconds the survey took.
//!   The loader then applies the paper's survey-time rule: D1 counts 0 s
//!   per survey, D12 and D2 count 5 s for participants without a
//!   limitation and the logged time for the others.
//! - One row per baseline condition: its end-of-condition survey, without
//!   a query (these give each participant's WL_0).
//! - The end-of-condition surveys of query conditions stay in the raw logs
//!   only: the format has no row kind for them, and as rows without a
//!   query they would be mistaken for baseline surveys.
//! - Participant ids are the pseudonyms; tokens are never exported.

use std::path::Path;

use hil_core::{HilError, Result};
use hil_workload::study::{PosedQuery, Study, StudyRecord};

use super::design::Design;
use super::log::{Event, read};
use super::server::{participant_logs, stored_design};

/// The study CSV records of the data folder `dir`, validated by the
/// study loader. A cut-short last line of a log (a crash mid-write) is
/// ignored, as the server ignores it.
pub fn export(dir: &Path) -> Result<Study> {
    let config = stored_design(dir)?.ok_or_else(|| {
        HilError::invalid_input(
            "data folder",
            format!(
                "{} has no design.json: not a study data folder",
                dir.display()
            ),
        )
    })?;
    let design = Design::new(config)?;
    let mut records = Vec::new();
    for path in participant_logs(dir)? {
        let (lines, _) = read(&path)?;
        let Some(Event::Enrolled {
            participant,
            population,
            ..
        }) = lines.first().map(|l| &l.event)
        else {
            return Err(hil_textdata::data_error(
                &path,
                1,
                "event",
                "the first line must be `enrolled`",
            ));
        };
        // When each query of each condition appeared.
        let mut shown = std::collections::HashMap::new();
        for (i, line) in lines.iter().enumerate() {
            match &line.event {
                Event::QueryShown {
                    condition,
                    query,
                    task_s,
                    difficulty,
                    response,
                } => {
                    shown.insert(
                        (condition.clone(), *query),
                        (*task_s, *difficulty, *response),
                    );
                }
                Event::SurveySubmitted {
                    condition,
                    query,
                    task_s,
                    tlx,
                    survey_time_s,
                } => {
                    let Some((_, cond)) = design.condition(condition) else {
                        return Err(hil_textdata::data_error(
                            &path,
                            i + 1,
                            "condition",
                            format!("`{condition}` is not in the design"),
                        ));
                    };
                    let (query_time_s, posed) = match (query, cond.queries) {
                        (Some(k), Some(f)) => {
                            let Some(&(t, difficulty, response)) =
                                shown.get(&(condition.clone(), *k))
                            else {
                                return Err(hil_textdata::data_error(
                                    &path,
                                    i + 1,
                                    "query",
                                    format!("a survey after query {k}, which was never shown"),
                                ));
                            };
                            (
                                t,
                                Some(PosedQuery {
                                    difficulty,
                                    response,
                                    interval_min: f.interval_min,
                                }),
                            )
                        }
                        (None, None) => (*task_s, None),
                        // End of a query condition: raw log only (see above).
                        (None, Some(_)) => continue,
                        (Some(_), None) => {
                            return Err(hil_textdata::data_error(
                                &path,
                                i + 1,
                                "query",
                                "a query in a baseline condition",
                            ));
                        }
                    };
                    records.push(StudyRecord {
                        participant: participant.clone(),
                        population: *population,
                        condition: condition.clone(),
                        query_time_s,
                        query: posed,
                        distraction: cond.distraction,
                        tlx: *tlx,
                        survey_time_s: Some(*survey_time_s),
                        line: 0,
                    });
                }
                _ => {}
            }
        }
    }
    if records.is_empty() {
        return Err(HilError::invalid_input(
            "data folder",
            format!("{} has no submitted survey yet", dir.display()),
        ));
    }
    Study::from_records(dir.join("export"), records)
}
