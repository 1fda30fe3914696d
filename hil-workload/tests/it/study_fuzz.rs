//! Property tests of the study CSV reader and everything built on it:
//! mutated valid studies (truncations, bit flips, junk, huge and
//! non-finite numbers) are either read or refused with an error that names
//! the file and a line, never a panic; and what is read summarises (or is
//! refused) the same way, and writes back to an equal study.

use std::path::Path;

use hil_conformance::mutate::mutated;
use hil_core::HilError;
use hil_workload::bundle::StudySummary;
use hil_workload::datasets::{Dataset, DatasetId};
use hil_workload::study::{Study, StudyRecord};
use proptest::prelude::*;

const FILE: &str = "fuzz/study.csv";

/// A small valid study: two populations, baselines, queries, quoted
/// fields, a CRLF line and a blank line.
const STUDY: &str = "participant,population,condition,query_time_s,difficulty,response_type,distraction,interval_min,mental,temporal,performance,effort,frustration,survey_time_s\n\
p1,no_limitation,base,330,,,easy,,2,1,4,2,1,\n\
p1,no_limitation,c1,60,easy,mcq,none,1,3,2,4,3,1,12.5\n\
p1,no_limitation,c1,120,hard,open_ended,none,1,4,3,3,4,2,20\r\n\
\n\
\"p2\",\"mobility_limitation\",\"base\",\"330\",,,\"hard\",,\"3\",\"2\",\"3\",\"3\",\"2\",\n\
p2,mobility_limitation,\"c, 2\",120,easy,bounding_box,easy,2,2,2,4,2,1,31.2\n\
p2,mobility_limitation,\"c, 2\",240,hard,mcq,easy,2,5,4,2,5,4,\n";

/// The error names the study file and a line in it.
fn assert_located(e: &HilError) -> Result<(), TestCaseError> {
    match e {
        HilError::Data { path, record, .. } => {
            prop_assert_eq!(path.as_path(), Path::new(FILE), "{}", e);
            prop_assert!(*record >= 1, "{}", e);
            Ok(())
        }
        other => Err(TestCaseError::fail(format!(
            "not a located data error: {other:?}"
        ))),
    }
}

fn without_lines(s: &Study) -> Vec<StudyRecord> {
    s.records().iter().map(StudyRecord::without_line).collect()
}

fn check(bytes: &[u8]) -> Result<(), TestCaseError> {
    // Non-UTF-8 files are refused by `hil_core::files::read_text` (tested
    // there); the parser sees text, so invalid bytes become U+FFFD.
    let text = String::from_utf8_lossy(bytes);
    let study = match Study::parse(&text, Path::new(FILE)) {
        Ok(s) => s,
        Err(e) => return assert_located(&e),
    };
    for id in DatasetId::ALL {
        if let Err(e) = Dataset::build(&study, id) {
            assert_located(&e)?;
        }
    }
    if let Err(e) = StudySummary::of(&study) {
        assert_located(&e)?;
    }
    let again = Study::parse(&study.to_csv(), Path::new(FILE))
        .map_err(|e| TestCaseError::fail(format!("written study does not read back: {e}")))?;
    prop_assert_eq!(without_lines(&again), without_lines(&study));
    Ok(())
}

#[test]
fn the_unmutated_study_is_valid() {
    let s = Study::parse(STUDY, Path::new(FILE)).unwrap();
    assert_eq!(s.records().len(), 6);
    assert_eq!(s.records()[4].condition, "c, 2");
    StudySummary::of(&s).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn mutated_studies_are_read_or_refused_with_a_located_error(
        bytes in mutated(STUDY.as_bytes().to_vec(), 4)
    ) {
        check(&bytes)?;
    }

    #[test]
    fn random_bytes_are_refused_with_a_located_error(
        bytes in proptest::collection::vec(any::<u8>(), 0..400)
    ) {
        check(&bytes)?;
    }
}

#[test]
fn a_file_that_is_not_utf8_is_refused_naming_it() {
    let dir = std::env::temp_dir().join(format!("hil-study-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("latin1.csv");
    let mut bytes = STUDY.as_bytes().to_vec();
    bytes.extend_from_slice(b"p\xe9,no_limitation,c9,60,easy,mcq,none,1,1,1,1,1,1,\n");
    std::fs::write(&path, bytes).unwrap();
    match Study::load(&path).unwrap_err() {
        HilError::Io {
            path: p, source, ..
        } => {
            assert_eq!(p, path);
            assert_eq!(source.kind(), std::io::ErrorKind::InvalidData);
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).ok();
}
