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
//! - The end-of-condition surveys of query conditions go to a second CSV
//!   ([`Export::write`]): the study format has no row kind for them, and as
//!   rows without a query they would be mistaken for baseline surveys.
//!   Together the two files hold every survey `hil study status` counts.
//! - Participant ids are the pseudonyms; tokens are never exported.

use std::path::Path;

use std::path::PathBuf;

use hil_core::{HilError, Result};
use hil_workload::study::{Population, PosedQuery, Study, StudyRecord};
use hil_workload::tlx::TlxAnswers;

use crate::design::Design;
use crate::log::{Event, read};
use crate::server::{participant_logs, stored_design};

/// The survey at the end of a query condition (the second CSV's row).
#[derive(Clone, Debug, PartialEq)]
pub struct EndSurvey {
    /// Pseudonymous participant id.
    pub participant: String,
    /// The participant's population.
    pub population: Population,
    /// Condition id.
    pub condition: String,
    /// Study seconds on the task clock when the condition ended.
    pub task_s: f64,
    /// The answers.
    pub tlx: TlxAnswers,
    /// Real seconds the survey took.
    pub survey_time_s: f64,
}

/// Everything a data folder's surveys export to.
#[derive(Debug)]
pub struct Export {
    /// The study CSV: surveys after queries and of baselines.
    pub study: Study,
    /// The end-of-condition surveys of query conditions.
    pub end_of_condition: Vec<EndSurvey>,
}

/// Header of the end-of-condition CSV.
pub const END_SURVEYS_HEADER: &str = "participant,population,condition,task_s,mental,temporal,performance,effort,frustration,survey_time_s";

impl Export {
    /// Where [`write`](Self::write) puts the end-of-condition surveys for a
    /// study CSV at `study_csv`: beside it, `<stem>.end_of_condition.csv`.
    ///
    /// ```
    /// let p = hil_study::export::Export::end_of_condition_path("out/study.csv".as_ref());
    /// assert_eq!(p, std::path::Path::new("out/study.end_of_condition.csv"));
    /// ```
    pub fn end_of_condition_path(study_csv: &Path) -> PathBuf {
        let stem = study_csv
            .file_stem()
            .map_or("study".into(), |s| s.to_string_lossy());
        study_csv.with_file_name(format!("{stem}.end_of_condition.csv"))
    }

    /// The end-of-condition surveys as CSV ([`END_SURVEYS_HEADER`]).
    pub fn end_of_condition_csv(&self) -> String {
        let mut out = format!("{END_SURVEYS_HEADER}\n");
        for e in &self.end_of_condition {
            let t = &e.tlx;
            out.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{}\n",
                e.participant,
                e.population.as_str(),
                e.condition,
                e.task_s,
                t.mental,
                t.temporal,
                t.performance,
                t.effort,
                t.frustration,
                e.survey_time_s
            ));
        }
        out
    }

    /// Writes the study CSV to `study_csv` and the end-of-condition surveys
    /// beside it ([`end_of_condition_path`](Self::end_of_condition_path));
    /// returns that second path.
    pub fn write(&self, study_csv: &Path) -> Result<PathBuf> {
        self.study.write(study_csv)?;
        let end = Self::end_of_condition_path(study_csv);
        std::fs::write(&end, self.end_of_condition_csv())
            .map_err(|e| HilError::io("writing", &end, e))?;
        Ok(end)
    }

    /// How many surveys the two files hold together: what `hil study
    /// status` counts.
    pub fn surveys(&self) -> usize {
        self.study.records().len() + self.end_of_condition.len()
    }
}

/// The study CSV records of the data folder `dir`, validated by the
/// study loader (the end-of-condition surveys of query conditions are left
/// out: [`export_all`] has them too).
pub fn export(dir: &Path) -> Result<Study> {
    export_all(dir).map(|e| e.study)
}

/// Every survey of the data folder `dir`: the study CSV's records,
/// validated by the study loader, and the end-of-condition surveys. A
/// cut-short last line of a log (a crash mid-write) is ignored, as the
/// server ignores it.
pub fn export_all(dir: &Path) -> Result<Export> {
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
    let mut end_of_condition = Vec::new();
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
                        // End of a query condition: the second CSV.
                        (None, Some(_)) => {
                            end_of_condition.push(EndSurvey {
                                participant: participant.clone(),
                                population: *population,
                                condition: condition.clone(),
                                task_s: *task_s,
                                tlx: *tlx,
                                survey_time_s: *survey_time_s,
                            });
                            continue;
                        }
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
    Ok(Export {
        study: Study::from_records(dir.join("export"), records)?,
        end_of_condition,
    })
}
