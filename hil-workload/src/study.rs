//! The study-data format: one CSV row per TLX survey, with a validating
//! loader whose errors name the file, line and column.
//!
//! The file is RFC 4180 CSV (read with the `csv` crate through
//! [`hil_textdata::CsvFile`]): any field may be quoted, as spreadsheet
//! programs write them, and a quoted field may hold commas. Blank lines and
//! white space around fields are ignored; a UTF-8 byte-order mark is
//! allowed. Files are read through [`hil_core::files`] and may hold at most
//! [`hil_core::files::limits::STUDY`] bytes. Memory and time are linear in
//! the rows.
//!
//! Columns (a header row names them; any order; every column required, no
//! extras, no duplicates):
//!
//! | column | values |
//! |---|---|
//! | `participant` | participant id (non-empty text) |
//! | `population` | `no_limitation`, `mobility_limitation`, `occupational_therapist` |
//! | `condition` | condition id (non-empty text), unique per participant |
//! | `query_time_s` | seconds from the condition start (≥ 0) when the query was posed (or, for a survey without a query, when the survey was taken), on the task clock that excludes survey time |
//! | `difficulty` | `easy`, `hard`, or empty for a survey without a query |
//! | `response_type` | `mcq`, `bounding_box`, `open_ended`, or empty without a query |
//! | `distraction` | `none`, `easy`, `hard` |
//! | `interval_min` | `1` or `2`, or empty without a query |
//! | `mental`, `temporal`, `performance`, `effort`, `frustration` | TLX answers, integers 1..=5 |
//! | `survey_time_s` | seconds the survey took (≥ 0), or empty if not logged |
//!
//! A row with a query has `difficulty`, `response_type` and `interval_min`
//! all set; a row without (a baseline condition: distraction only) has all
//! three empty. Baseline surveys give each participant's initial workload
//! WL_0 (see [`crate::datasets`]).
//!
//! ```
//! use hil_workload::study::Study;
//! let csv = "participant,population,condition,query_time_s,difficulty,response_type,distraction,interval_min,mental,temporal,performance,effort,frustration,survey_time_s\n\
//!            p1,no_limitation,base,330,,,easy,,2,1,4,2,1,\n\
//!            p1,no_limitation,c1,60,easy,mcq,none,1,3,2,4,3,1,12.5\n";
//! let study = Study::parse(csv, "inline.csv".as_ref()).unwrap();
//! assert_eq!(study.records().len(), 2);
//! let bad = csv.replace("3,2,4,3,1,12.5", "3,2,4,7,1,12.5");
//! let err = Study::parse(&bad, "inline.csv".as_ref()).unwrap_err().to_string();
//! assert!(err.contains("inline.csv:3") && err.contains("effort"));
//! ```

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use hil_core::{Difficulty, Distraction, HilError, QueryKind, ResponseType, Result};
use hil_textdata::{CsvFile, StringRecord, csv_line, data_error};
use serde::{Deserialize, Serialize};

use crate::tlx::TlxAnswers;

/// The columns of the study CSV, in the order the writer uses.
pub const COLUMNS: [&str; 14] = [
    "participant",
    "population",
    "condition",
    "query_time_s",
    "difficulty",
    "response_type",
    "distraction",
    "interval_min",
    "mental",
    "temporal",
    "performance",
    "effort",
    "frustration",
    "survey_time_s",
];

/// Which population a participant belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Population {
    /// Participants without mobility limitations (dataset D1).
    NoLimitation,
    /// Participants with mobility limitations (D2).
    MobilityLimitation,
    /// Occupational therapists simulating limitations (D2).
    OccupationalTherapist,
}

impl Population {
    /// The CSV spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::NoLimitation => "no_limitation",
            Self::MobilityLimitation => "mobility_limitation",
            Self::OccupationalTherapist => "occupational_therapist",
        }
    }

    /// True for the populations of dataset D2.
    pub fn is_limited(self) -> bool {
        !matches!(self, Self::NoLimitation)
    }
}

/// The query posed before a survey.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PosedQuery {
    /// Query difficulty.
    pub difficulty: Difficulty,
    /// How the participant answered.
    pub response: ResponseType,
    /// Minutes between queries in this condition (1 or 2).
    pub interval_min: u8,
}

/// One survey row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyRecord {
    /// Participant id.
    pub participant: String,
    /// The participant's population.
    pub population: Population,
    /// Condition id.
    pub condition: String,
    /// Seconds from the condition start (task clock, survey time excluded).
    pub query_time_s: f64,
    /// The query, or `None` for a survey without one (baseline condition).
    pub query: Option<PosedQuery>,
    /// The concurrent distraction task.
    pub distraction: Distraction,
    /// The TLX answers.
    pub tlx: TlxAnswers,
    /// Logged survey duration in seconds, if any.
    pub survey_time_s: Option<f64>,
    /// 1-based line in the source file (0 for generated records).
    #[serde(skip)]
    pub line: usize,
}

impl StudyRecord {
    /// The hil-core query kind, if this row has a query.
    pub fn kind(&self) -> Option<QueryKind> {
        self.query.map(|q| QueryKind {
            response: q.response,
            difficulty: q.difficulty,
            distraction: self.distraction,
        })
    }

    /// The record without its source line: what it says, not where it
    /// stood (two parses of the same data written differently compare
    /// equal this way).
    pub fn without_line(&self) -> Self {
        Self {
            line: 0,
            ..self.clone()
        }
    }
}

/// A validated study: every record well-formed, at least one record.
#[derive(Clone, Debug)]
pub struct Study {
    source: PathBuf,
    records: Vec<StudyRecord>,
}

fn data_err(
    path: &Path,
    line: usize,
    field: impl Into<String>,
    why: impl Into<String>,
) -> HilError {
    data_error(path, line, &field.into(), why)
}

impl Study {
    /// Builds a study from records (e.g. generated ones), validating them.
    pub fn from_records(source: impl Into<PathBuf>, records: Vec<StudyRecord>) -> Result<Self> {
        let s = Self {
            source: source.into(),
            records,
        };
        s.validate()?;
        Ok(s)
    }

    /// Reads and validates a study CSV.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = hil_core::files::read_text(path, hil_core::files::limits::STUDY)?;
        Self::parse(&text, path)
    }

    /// Parses and validates study CSV text; `path` names it in errors.
    ///
    /// The text is RFC 4180 CSV: any field may be quoted (as spreadsheet
    /// programs write them), surrounding white space is ignored. Rows are
    /// parsed one at a time, so memory grows with the records, not more.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let mut csv = CsvFile::parse(text, path)?;
        let header_line = csv.header_line();
        let names: Vec<String> = csv.header().to_vec();
        let mut index: HashMap<&str, usize> = HashMap::new();
        for (i, name) in names.iter().enumerate() {
            let name = name.as_str();
            if !COLUMNS.contains(&name) {
                return Err(data_err(
                    path,
                    header_line,
                    format!("column {} (`{name}`)", i + 1),
                    format!(
                        "unknown column; expected the columns {}",
                        COLUMNS.join(", ")
                    ),
                ));
            }
            if index.insert(name, i).is_some() {
                return Err(data_err(
                    path,
                    header_line,
                    format!("column {} (`{name}`)", i + 1),
                    "duplicated column",
                ));
            }
        }
        if let Some(missing) = COLUMNS.iter().find(|c| !index.contains_key(*c)) {
            return Err(data_err(path, header_line, *missing, "missing column"));
        }
        let col = |name: &str| index[name];
        let mut records = Vec::new();
        let mut row = StringRecord::new();
        while let Some(line) = csv.next_record(&mut row)? {
            let cells: Vec<&str> = row.iter().collect();
            if cells.len() != names.len() {
                return Err(data_err(
                    path,
                    line,
                    "row",
                    format!(
                        "{} cells, but the header has {} columns",
                        cells.len(),
                        names.len()
                    ),
                ));
            }
            let cell = |name: &str| -> (&str, String) {
                let i = col(name);
                (cells[i], format!("column {} (`{name}`)", i + 1))
            };
            let req = |name: &str| -> Result<(&str, String)> {
                let (v, f) = cell(name);
                if v.is_empty() {
                    Err(data_err(path, line, f, "empty, but a value is required"))
                } else {
                    Ok((v, f))
                }
            };
            let enum_of = |name: &str, allowed: &[&str]| -> Result<Option<usize>> {
                let (v, f) = cell(name);
                if v.is_empty() {
                    return Ok(None);
                }
                allowed
                    .iter()
                    .position(|a| *a == v)
                    .map(Some)
                    .ok_or_else(|| {
                        data_err(
                            path,
                            line,
                            f,
                            format!(
                                "unknown value `{v}`; expected one of {}",
                                allowed.join(", ")
                            ),
                        )
                    })
            };
            // A query variable, spelled as hil-core's `FromStr` spells it.
            fn variable<T: std::str::FromStr<Err = HilError>>(
                (v, f): (&str, String),
                at: &dyn Fn(&str, String) -> HilError,
            ) -> Result<Option<T>> {
                if v.is_empty() {
                    return Ok(None);
                }
                v.parse::<T>().map(Some).map_err(|e| match e {
                    HilError::InvalidParameter { why, .. } => {
                        at(&f, format!("unknown value `{v}`; {why}"))
                    }
                    other => at(&f, other.to_string()),
                })
            }
            let at = |f: &str, why: String| data_err(path, line, f, why);
            let seconds = |name: &str, v: &str, f: &str| -> Result<f64> {
                let x: f64 = v
                    .parse()
                    .map_err(|_| data_err(path, line, f, format!("`{v}` is not a number")))?;
                if !x.is_finite() || x < 0.0 {
                    return Err(data_err(
                        path,
                        line,
                        f,
                        format!("{name} must be a finite number ≥ 0, got {v}"),
                    ));
                }
                Ok(x)
            };
            let (participant, _) = req("participant")?;
            let (condition, _) = req("condition")?;
            let pops = [
                "no_limitation",
                "mobility_limitation",
                "occupational_therapist",
            ];
            req("population")?;
            let population = [
                Population::NoLimitation,
                Population::MobilityLimitation,
                Population::OccupationalTherapist,
            ][enum_of("population", &pops)?.unwrap_or(0)];
            let (t, tf) = req("query_time_s")?;
            let query_time_s = seconds("a time", t, &tf)?;
            req("distraction")?;
            let distraction: Distraction = variable(cell("distraction"), &at)?.unwrap_or_default();
            let difficulty: Option<Difficulty> = variable(cell("difficulty"), &at)?;
            let response: Option<ResponseType> = variable(cell("response_type"), &at)?;
            let interval = enum_of("interval_min", &["1", "2"])?.map(|i| i as u8 + 1);
            let query = match (difficulty, response, interval) {
                (Some(difficulty), Some(response), Some(interval_min)) => Some(PosedQuery {
                    difficulty,
                    response,
                    interval_min,
                }),
                (None, None, None) => None,
                _ => {
                    let missing = [
                        ("difficulty", difficulty.is_none()),
                        ("response_type", response.is_none()),
                        ("interval_min", interval.is_none()),
                    ]
                    .into_iter()
                    .find(|(_, m)| *m)
                    .map(|(n, _)| n)
                    .unwrap_or("difficulty");
                    return Err(data_err(
                        path,
                        line,
                        cell(missing).1,
                        "a query row needs difficulty, response_type and interval_min all set (a survey without a query leaves all three empty)",
                    ));
                }
            };
            let mut likert = [0u8; 5];
            for (k, name) in ["mental", "temporal", "performance", "effort", "frustration"]
                .iter()
                .enumerate()
            {
                let (v, f) = req(name)?;
                likert[k] = v
                    .parse::<u8>()
                    .ok()
                    .filter(|a| (1..=5).contains(a))
                    .ok_or_else(|| {
                        data_err(
                            path,
                            line,
                            f,
                            format!("`{v}` is not a Likert answer: expected an integer in 1..=5"),
                        )
                    })?;
            }
            let tlx = TlxAnswers::new(likert[0], likert[1], likert[2], likert[3], likert[4])?;
            let (st, stf) = cell("survey_time_s");
            let survey_time_s = if st.is_empty() {
                None
            } else {
                Some(seconds("a survey time", st, &stf)?)
            };
            records.push(StudyRecord {
                participant: participant.to_string(),
                population,
                condition: condition.to_string(),
                query_time_s,
                query,
                distraction,
                tlx,
                survey_time_s,
                line,
            });
        }
        let s = Self {
            source: path.to_path_buf(),
            records,
        };
        s.validate()?;
        Ok(s)
    }

    /// Cross-row checks: non-empty; one population per participant; one
    /// distraction per condition; no two surveys at the same time.
    fn validate(&self) -> Result<()> {
        let path = &self.source;
        if self.records.is_empty() {
            return Err(data_err(path, 1, "(file)", "the dataset has no records"));
        }
        let mut pop: HashMap<&str, Population> = HashMap::new();
        let mut dist: HashMap<(&str, &str), Distraction> = HashMap::new();
        let mut seen: HashSet<(&str, &str, u64)> = HashSet::new();
        for (i, r) in self.records.iter().enumerate() {
            let line = if r.line > 0 { r.line } else { i + 2 };
            // Any text is an id (the CSV quotes what needs quoting), but
            // the reader trims cells, so surrounding white space would not
            // survive writing and reading back.
            for (field, id) in [("participant", &r.participant), ("condition", &r.condition)] {
                if id.is_empty() || id.trim() != id {
                    return Err(data_err(
                        path,
                        line,
                        field,
                        "must be non-empty, without surrounding white space",
                    ));
                }
            }
            if !(r.query_time_s.is_finite() && r.query_time_s >= 0.0) {
                return Err(data_err(
                    path,
                    line,
                    "query_time_s",
                    format!("must be finite and ≥ 0, got {}", r.query_time_s),
                ));
            }
            if let Some(s) = r.survey_time_s
                && !(s.is_finite() && s >= 0.0)
            {
                return Err(data_err(
                    path,
                    line,
                    "survey_time_s",
                    format!("must be finite and ≥ 0, got {s}"),
                ));
            }
            if let Some(q) = r.query
                && !(1..=2).contains(&q.interval_min)
            {
                return Err(data_err(
                    path,
                    line,
                    "interval_min",
                    format!("must be 1 or 2, got {}", q.interval_min),
                ));
            }
            TlxAnswers::new(
                r.tlx.mental,
                r.tlx.temporal,
                r.tlx.performance,
                r.tlx.effort,
                r.tlx.frustration,
            )
            .map_err(|e| data_err(path, line, "tlx", e.to_string()))?;
            if let Some(p) = pop.insert(&r.participant, r.population)
                && p != r.population
            {
                return Err(data_err(
                    path,
                    line,
                    "population",
                    format!(
                        "participant `{}` was `{}` on an earlier row, `{}` here",
                        r.participant,
                        p.as_str(),
                        r.population.as_str()
                    ),
                ));
            }
            if let Some(d) = dist.insert((&r.participant, &r.condition), r.distraction)
                && d != r.distraction
            {
                return Err(data_err(
                    path,
                    line,
                    "distraction",
                    format!(
                        "condition `{}` of participant `{}` has two distraction settings",
                        r.condition, r.participant
                    ),
                ));
            }
            if !seen.insert((&r.participant, &r.condition, r.query_time_s.to_bits())) {
                return Err(data_err(
                    path,
                    line,
                    "query_time_s",
                    format!(
                        "duplicate survey: participant `{}`, condition `{}` already has a row at {} s",
                        r.participant, r.condition, r.query_time_s
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The records, in file order.
    pub fn records(&self) -> &[StudyRecord] {
        &self.records
    }

    /// Where the study came from (a file, or a label for generated data).
    pub fn source(&self) -> &Path {
        &self.source
    }

    /// Writes the study as CSV ([`Study::to_csv`]) to `path`, creating its
    /// folder if needed.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        hil_core::files::write_text(path, &self.to_csv())
    }

    /// Renders the study as CSV in the documented format (RFC 4180: a
    /// field is quoted only if it needs to be).
    pub fn to_csv(&self) -> String {
        let mut out = csv_line(COLUMNS);
        for r in &self.records {
            let (d, rt, iv) = match r.query {
                Some(q) => (
                    q.difficulty.as_str(),
                    q.response.as_str(),
                    q.interval_min.to_string(),
                ),
                None => ("", "", String::new()),
            };
            out.push_str(&csv_line([
                r.participant.as_str(),
                r.population.as_str(),
                r.condition.as_str(),
                &r.query_time_s.to_string(),
                d,
                rt,
                r.distraction.as_str(),
                &iv,
                &r.tlx.mental.to_string(),
                &r.tlx.temporal.to_string(),
                &r.tlx.performance.to_string(),
                &r.tlx.effort.to_string(),
                &r.tlx.frustration.to_string(),
                &r.survey_time_s.map(|s| s.to_string()).unwrap_or_default(),
            ]));
        }
        out
    }

    /// Writes the study as CSV.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        std::fs::write(path, self.to_csv()).map_err(|e| HilError::io("writing", path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "participant,population,condition,query_time_s,difficulty,response_type,distraction,interval_min,mental,temporal,performance,effort,frustration,survey_time_s";

    fn parse(body: &str) -> Result<Study> {
        Study::parse(&format!("{HEADER}\n{body}"), Path::new("s.csv"))
    }

    fn err(body: &str) -> String {
        parse(body).unwrap_err().to_string()
    }

    #[test]
    fn good_rows_round_trip() {
        let s = parse("p1,mobility_limitation,c1,60,hard,open_ended,easy,2,1,2,3,4,5,30.5\np1,mobility_limitation,b,330,,,hard,,1,1,1,1,1,\n").unwrap();
        assert_eq!(s.records().len(), 2);
        let again = Study::parse(&s.to_csv(), Path::new("s.csv")).unwrap();
        assert_eq!(again.records(), s.records());
    }

    #[test]
    fn a_spreadsheet_export_reads_like_the_plain_file() {
        let plain = "p1,mobility_limitation,c1,60,hard,open_ended,easy,2,1,2,3,4,5,30.5\np1,mobility_limitation,b,330,,,hard,,1,1,1,1,1,\n";
        // Every field quoted, CRLF line ends, a byte-order mark and a blank line.
        let quoted: String = std::iter::once(HEADER)
            .chain(plain.lines())
            .map(|l| {
                let cells: Vec<String> = l.split(',').map(|c| format!("\"{c}\"")).collect();
                cells.join(",") + "\r\n\r\n"
            })
            .collect();
        let a = parse(plain).unwrap();
        let b = Study::parse(&format!("\u{feff}{quoted}"), Path::new("s.csv")).unwrap();
        let strip = |s: &Study| -> Vec<StudyRecord> {
            s.records().iter().map(StudyRecord::without_line).collect()
        };
        assert_eq!(strip(&a), strip(&b));
        // Lines are counted in the file, blank ones included.
        assert_eq!(b.records()[1].line, 5);
    }

    #[test]
    fn ids_with_commas_and_quotes_round_trip() {
        let s = parse(
            "\"Smith, J.\",no_limitation,\"the \"\"easy\"\" one\",60,easy,mcq,none,1,1,2,3,4,5,\n",
        )
        .unwrap();
        assert_eq!(s.records()[0].participant, "Smith, J.");
        assert_eq!(s.records()[0].condition, "the \"easy\" one");
        let again = Study::parse(&s.to_csv(), Path::new("s.csv")).unwrap();
        assert_eq!(again.records(), s.records());
    }

    #[test]
    fn errors_give_the_line_a_record_starts_on() {
        // A quoted line break in a condition id: the next record is on line 4.
        let e = parse("p1,no_limitation,\"c\n1\",60,easy,mcq,none,1,1,2,3,4,5,\np1,no_limitation,c2,60,easy,mcq,none,1,1,2,3,4,9,\n").unwrap_err();
        match e {
            HilError::Data { record, field, .. } => {
                assert_eq!(record, 4);
                assert_eq!(field, "column 13 (`frustration`)");
            }
            other => panic!("{other:?}"),
        }
        match parse("p1,no_limitation,c1,60,easy,mcq,none,1,1,2,3\n").unwrap_err() {
            HilError::Data { record, field, .. } => {
                assert_eq!((record, field.as_str()), (2, "row"))
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_inputs_name_file_line_and_column() {
        let e = err("p1,no_limitation,c1,60,easy,mcq,none,1,1,2,3,4,6,\n");
        assert!(
            e.contains("s.csv:2") && e.contains("column 13 (`frustration`)"),
            "{e}"
        );
        let e = err("p1,no_limitation,c1,60,medium,mcq,none,1,1,2,3,4,5,\n");
        assert!(
            e.contains("s.csv:2") && e.contains("`difficulty`") && e.contains("medium"),
            "{e}"
        );
        let e = err("p1,no_limitation,c1,-3,easy,mcq,none,1,1,2,3,4,5,\n");
        assert!(e.contains("query_time_s") && e.contains("≥ 0"), "{e}");
        let e = err("p1,no_limitation,c1,3,easy,mcq,none,1,1,2,3,4,5,-1\n");
        assert!(e.contains("survey_time_s"), "{e}");
        let e = err("p1,no_limitation,c1,3,easy,,none,1,1,2,3,4,5,\n");
        assert!(e.contains("response_type"), "{e}");
        let e = err("p1,martian,c1,3,easy,mcq,none,1,1,2,3,4,5,\n");
        assert!(e.contains("population") && e.contains("martian"), "{e}");
        let e = err("");
        assert!(e.contains("no records"), "{e}");
        let e = Study::parse("participant,population\n", Path::new("s.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing column"), "{e}");
        let dup = HEADER.replace("frustration", "mental");
        let e = Study::parse(&format!("{dup}\n"), Path::new("s.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("duplicated column") && e.contains("column 13"),
            "{e}"
        );
        let e = err(
            "p1,no_limitation,c1,3,easy,mcq,none,1,1,2,3,4,5,\np1,no_limitation,c1,3,easy,mcq,none,1,1,2,3,4,5,\n",
        );
        assert!(e.contains("s.csv:3") && e.contains("duplicate"), "{e}");
        let e = Study::parse("", Path::new("s.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("empty"), "{e}");
    }
}
