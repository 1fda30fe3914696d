//! # hil-textdata
//!
//! Reading tabular text files (study data, food tables, published figures),
//! with errors that name the file, line and field.
//!
//! Two readers, for two formats:
//!
//! - [`CsvFile`]: RFC 4180 CSV (the `csv` crate), for files people make or
//!   export, such as study data: fields may be quoted (as spreadsheet
//!   programs write them), quoted fields may hold commas, quotes and line
//!   breaks. [`csv_line`] writes a record the same way.
//! - [`TextRecords`]: the line tables hil ships as data, where `#` starts a
//!   comment line and a last free-text column may hold unquoted commas
//!   (so they are not CSV); it hands each line to its parser whole.
//!
//! Both skip blank lines, take the first remaining line as the header and
//! build their errors with [`data_error`].

use std::path::{Path, PathBuf};

use hil_core::error::{HilError, Result};

/// A record read by [`CsvFile::next_record`] (the `csv` crate's type, so
/// callers need not depend on that crate).
pub use csv::StringRecord;

/// The located error of every tabular reader: `field` at `line` of `path`.
pub fn data_error(path: &Path, line: usize, field: &str, why: impl Into<String>) -> HilError {
    HilError::Data {
        path: path.to_path_buf(),
        record: line,
        field: field.to_string(),
        why: why.into(),
    }
}

/// An RFC 4180 CSV text read record by record: the header, then each
/// record with the 1-based line it starts on. Cells are trimmed of
/// surrounding white space (a quoted field starts with its quote, right
/// after the comma, as RFC 4180 has it); blank lines are skipped; records may have any
/// number of cells (the caller compares them with the header, so it can
/// say which line is short).
///
/// ```
/// use std::path::Path;
/// use hil_textdata::CsvFile;
/// let text = "name,note\n\"kiwi\",\"green, sour\"\n\npear ,\"says \"\"hi\"\"\"\n";
/// let mut csv = CsvFile::parse(text, Path::new("f.csv")).unwrap();
/// assert_eq!(csv.header(), ["name", "note"]);
/// let mut rec = hil_textdata::StringRecord::new();
/// assert_eq!(csv.next_record(&mut rec).unwrap(), Some(2));
/// assert_eq!(&rec[1], "green, sour");
/// assert_eq!(csv.next_record(&mut rec).unwrap(), Some(4));
/// assert_eq!((&rec[0], &rec[1]), ("pear", "says \"hi\""));
/// assert_eq!(csv.next_record(&mut rec).unwrap(), None);
/// let e = csv.error(4, "note", "too chatty");
/// assert!(matches!(e, hil_core::HilError::Data { record: 4, .. }));
/// assert!(CsvFile::parse("\n \n", Path::new("f.csv")).is_err());
/// ```
pub struct CsvFile<'a> {
    path: PathBuf,
    text: &'a str,
    reader: csv::Reader<&'a [u8]>,
    header_line: usize,
    header: Vec<String>,
    /// Line numbers are counted here, not taken from the `csv` crate, whose
    /// line count skips blank lines and `\r\n` pairs: `lines_before` line
    /// breaks precede byte `scanned` of `text`.
    scanned: usize,
    lines_before: usize,
}

impl std::fmt::Debug for CsvFile<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvFile")
            .field("path", &self.path)
            .field("header_line", &self.header_line)
            .field("header", &self.header)
            .finish_non_exhaustive()
    }
}

impl<'a> CsvFile<'a> {
    /// Reads the header of `text` (read from `path`); a text without one
    /// is an error at line 1, field `header`. A UTF-8 byte-order mark
    /// (which some spreadsheet programs write) is ignored.
    ///
    /// A quoted field still open at the end of the text (a last line
    /// ending in a lone `"`) is an error at the line the quote opened:
    /// the `csv` crate would close it silently, where RFC 4180 (and
    /// Python's `csv` in strict mode: "unexpected end of data") refuse it.
    pub fn parse(text: &'a str, path: &Path) -> Result<Self> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        if let Some(line) = unclosed_quote(text) {
            return Err(data_error(
                path,
                line,
                "record",
                "not valid CSV: a quoted field opened on this line is never closed",
            ));
        }
        let reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut file = Self {
            path: path.to_path_buf(),
            text,
            reader,
            scanned: 0,
            lines_before: 0,
            header_line: 1,
            header: Vec::new(),
        };
        let mut rec = StringRecord::new();
        let Some(line) = file.next_record(&mut rec)? else {
            return Err(data_error(
                path,
                1,
                "header",
                "the file is empty: expected a header row",
            ));
        };
        file.header_line = line;
        file.header = rec.iter().map(str::to_string).collect();
        Ok(file)
    }

    /// The header's cells, trimmed.
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// The 1-based line of the header.
    pub fn header_line(&self) -> usize {
        self.header_line
    }

    /// The file, for errors.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Reads the next non-blank record into `record` (reused, so reading a
    /// large file allocates little) and returns the line it starts on, or
    /// `None` at the end of the text.
    pub fn next_record(&mut self, record: &mut StringRecord) -> Result<Option<usize>> {
        loop {
            let more = match self.reader.read_record(record) {
                Ok(more) => more,
                Err(e) => {
                    let line = e.position().map_or(0, |p| self.line_at(p.byte()));
                    return Err(self.error(line, "record", format!("not valid CSV: {e}")));
                }
            };
            if !more {
                return Ok(None);
            }
            // A line of white space only is blank, not a record of one empty cell.
            if record.len() == 1 && record[0].is_empty() {
                continue;
            }
            let line = record.position().map_or(0, |p| self.line_at(p.byte()));
            return Ok(Some(line));
        }
    }

    /// The 1-based line of the record the `csv` crate places at byte
    /// `offset`: that offset may point at the line breaks before it, so
    /// they are skipped. Offsets only grow, so counting is linear overall.
    fn line_at(&mut self, offset: u64) -> usize {
        let bytes = self.text.as_bytes();
        let mut start = (offset as usize).min(bytes.len());
        while start < bytes.len() && matches!(bytes[start], b'\r' | b'\n') {
            start += 1;
        }
        if start < self.scanned {
            return bytecount_newlines(&bytes[..start]) + 1;
        }
        self.lines_before += bytecount_newlines(&bytes[self.scanned..start]);
        self.scanned = start;
        self.lines_before + 1
    }

    /// An error about `field` at `line` of this file.
    pub fn error(&self, line: usize, field: &str, why: impl Into<String>) -> HilError {
        data_error(&self.path, line, field, why)
    }
}

/// The 1-based line of a quoted field that `text` leaves open, if any.
/// Quotes are read as the `csv` crate reads them: a field is quoted when
/// its first byte is `"`, `""` inside it is a quote, and a `"` inside an
/// unquoted field is a plain character. One pass, no allocation.
fn unclosed_quote(text: &str) -> Option<usize> {
    #[derive(PartialEq)]
    enum State {
        FieldStart,
        Unquoted,
        Quoted,
        QuoteInQuoted,
    }
    let mut state = State::FieldStart;
    let (mut line, mut opened_at) = (1, 1);
    for &b in text.as_bytes() {
        let separator = matches!(b, b',' | b'\n' | b'\r');
        state = match state {
            State::FieldStart | State::Unquoted | State::QuoteInQuoted if separator => {
                State::FieldStart
            }
            State::FieldStart if b == b'"' => {
                opened_at = line;
                State::Quoted
            }
            State::Quoted if b == b'"' => State::QuoteInQuoted,
            State::Quoted => State::Quoted,
            State::QuoteInQuoted if b == b'"' => State::Quoted,
            _ => State::Unquoted,
        };
        if b == b'\n' {
            line += 1;
        }
    }
    (state == State::Quoted).then_some(opened_at)
}

fn bytecount_newlines(bytes: &[u8]) -> usize {
    bytes.iter().filter(|&&b| b == b'\n').count()
}

/// One CSV record as RFC 4180 writes it (a field is quoted only when it
/// holds a comma, a quote or a line break), with
/// a trailing newline; [`CsvFile`] reads it back to the same cells (cells
/// without surrounding white space, which the reader trims).
///
/// ```
/// use hil_textdata::csv_line;
/// assert_eq!(csv_line(["p1", "a, b", ""]), "p1,\"a, b\",\n");
/// ```
pub fn csv_line<I, S>(fields: I) -> String
where
    I: IntoIterator<Item = S>,
    S: AsRef<[u8]>,
{
    let mut w = csv::WriterBuilder::new()
        .quote_style(csv::QuoteStyle::Necessary)
        .from_writer(Vec::new());
    w.write_record(fields)
        .expect("writing CSV into memory cannot fail");
    let bytes = w.into_inner().expect("writing CSV into memory cannot fail");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

/// A data file split into its header and its records, with line numbers.
///
/// ```
/// use std::path::Path;
/// use hil_textdata::TextRecords;
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
        let header = lines
            .next()
            .ok_or_else(|| data_error(path, 1, "header", "the file is empty"))?;
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
        data_error(&self.path, line, field, why)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(text: &str) -> Vec<(usize, Vec<String>)> {
        let mut f = CsvFile::parse(text, Path::new("t.csv")).unwrap();
        let mut out = vec![(f.header_line(), f.header().to_vec())];
        let mut rec = StringRecord::new();
        while let Some(line) = f.next_record(&mut rec).unwrap() {
            out.push((line, rec.iter().map(str::to_string).collect()));
        }
        out
    }

    #[test]
    fn line_numbers_count_blank_lines_crlf_and_quoted_line_breaks() {
        let text = "\u{feff}\r\na,b\r\n\r\nx,y\r\n  \r\nz,\"multi\nline\"\n\n\nq ,\"r\"\n";
        let got = lines(text);
        let want: Vec<(usize, Vec<String>)> = [
            (2, ["a", "b"]),
            (4, ["x", "y"]),
            (6, ["z", "multi\nline"]),
            (10, ["q", "r"]),
        ]
        .into_iter()
        .map(|(l, c)| (l, c.iter().map(|s| s.to_string()).collect()))
        .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn csv_line_round_trips_through_the_reader() {
        let fields = ["plain", "a, b", "say \"hi\"", "two\nlines", ""];
        let text = format!(
            "{}{}",
            csv_line(["c1", "c2", "c3", "c4", "c5"]),
            csv_line(fields)
        );
        let got = lines(&text);
        assert_eq!(got[1].0, 2);
        assert_eq!(got[1].1, fields);
    }

    #[test]
    fn a_quoted_field_left_open_is_refused_at_its_line() {
        for (text, line) in [
            ("a,b\n1,\"", 2),
            ("a,b\n1,\"x\n\n2,3\n", 2),
            ("a,b\n1,\"x\"\"\n", 2),
            ("\"a,b\n", 1),
        ] {
            match CsvFile::parse(text, Path::new("t.csv")).unwrap_err() {
                HilError::Data { record, field, .. } => {
                    assert_eq!((record, field.as_str()), (line, "record"), "{text:?}")
                }
                other => panic!("{other:?}"),
            }
        }
        // Closed quotes, escaped quotes and a quote inside an unquoted
        // field are fine.
        for text in ["a,b\n1,\"\"\n", "a,b\n1,\"x\"\"y\"\n", "a,b\n1,x\"y\n"] {
            assert!(CsvFile::parse(text, Path::new("t.csv")).is_ok(), "{text:?}");
        }
    }

    #[test]
    fn empty_text_is_a_header_error_at_line_1() {
        for text in ["", "\n\n", "  \r\n"] {
            match CsvFile::parse(text, Path::new("t.csv")).unwrap_err() {
                HilError::Data { record, field, .. } => {
                    assert_eq!((record, field.as_str()), (1, "header"))
                }
                other => panic!("{other:?}"),
            }
        }
    }
}
