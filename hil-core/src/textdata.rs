//! Small line-oriented data files (the CSV tables hil ships as data): blank
//! lines and `#` comments skipped, the first remaining line the header, and
//! errors that name the file, line and field. One reader for every such file,
//! so they all treat comments and report errors alike.

use std::path::{Path, PathBuf};

use crate::error::{HilError, Result};

/// A data file split into its header and its records, with line numbers.
///
/// ```
/// use std::path::Path;
/// use hil_core::textdata::TextRecords;
/// let t = TextRecords::parse("# rates\nfood,rate\n\nkiwi,0.5\n", Path::new("r.csv")).unwrap();
/// assert_eq!(t.header, (2, "food,rate"));
/// assert_eq!(t.records, vec![(4, "kiwi,0.5")]);
/// let e = t.error(4, "rate", "too high");
/// assert!(matches!(e, hil_core::HilError::Data { record: 4, .. }));
/// assert!(TextRecords::parse("# only a comment\n", Path::new("r.csv")).is_err());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct TextRecords<'a> {
    /// The file, for errors.
    pub path: PathBuf,
    /// (1-based line, text) of the header.
    pub header: (usize, &'a str),
    /// (1-based line, trimmed text) of every record, in order.
    pub records: Vec<(usize, &'a str)>,
}

impl<'a> TextRecords<'a> {
    /// Splits `text` (read from `path`); a file without a header line is an
    /// error at line 1.
    pub fn parse(text: &'a str, path: &Path) -> Result<Self> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let header = lines.next().ok_or_else(|| HilError::Data {
            path: path.to_path_buf(),
            record: 1,
            field: "header".into(),
            why: "the file is empty".into(),
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            header,
            records: lines.collect(),
        })
    }

    /// The header's comma-separated column names, trimmed.
    pub fn columns(&self) -> Vec<&'a str> {
        self.header.1.split(',').map(str::trim).collect()
    }

    /// An error about `field` at `line` of this file.
    pub fn error(&self, line: usize, field: &str, why: impl Into<String>) -> HilError {
        HilError::Data {
            path: self.path.clone(),
            record: line,
            field: field.to_string(),
            why: why.into(),
        }
    }
}
