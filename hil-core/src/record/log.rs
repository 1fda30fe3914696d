//! The log file: durable appends, and reading back with a torn last line
//! detected and discarded.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::error::{HilError, Result};
use crate::record::format::{FORMAT_NAME, FORMAT_VERSION, Header, Record};

/// An append-only JSONL file whose every line reaches the disk (fsync)
/// before [`RecordLog::append`] returns.
#[derive(Debug)]
pub struct RecordLog {
    path: PathBuf,
    file: File,
    lines: usize,
}

/// A logged record with its line number (1-based) and exact text.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedRecord {
    /// 1-based line number.
    pub line: usize,
    /// The line, without its newline.
    pub text: String,
    /// The parsed record.
    pub record: Record,
}

/// What an existing log holds.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedSession {
    /// The header (line 1).
    pub header: Header,
    /// Every record after the header, in order.
    pub records: Vec<LoggedRecord>,
    /// Bytes of an incomplete last line that were cut off.
    pub truncated_bytes: u64,
}

impl RecordLog {
    /// Creates a new log at `path` starting with `header`. Refuses to
    /// overwrite an existing file (it may hold a session to resume).
    pub fn create(path: &Path, header: Header) -> Result<Self> {
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|e| HilError::io("creating", path, e))?;
        sync_parent_dir(path);
        let mut log = Self {
            path: path.to_path_buf(),
            file,
            lines: 0,
        };
        log.append(&Record::Header(header))?;
        Ok(log)
    }

    /// Opens an existing log for resuming: reads and validates every line,
    /// cuts off an incomplete last line (a write the process did not finish,
    /// so the robot never acted on it) and positions for appending.
    pub fn open(path: &Path) -> Result<(Self, LoggedSession)> {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| HilError::io("opening", path, e))?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)
            .map_err(|e| HilError::io("reading", path, e))?;
        let complete = bytes.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1);
        let truncated_bytes = (bytes.len() - complete) as u64;
        let session = parse(path, &bytes[..complete], truncated_bytes)?;
        if truncated_bytes > 0 {
            file.set_len(complete as u64)
                .and_then(|()| file.sync_data())
                .map_err(|e| HilError::io("truncating", path, e))?;
        }
        file.seek(SeekFrom::End(0))
            .map_err(|e| HilError::io("seeking in", path, e))?;
        let log = Self {
            path: path.to_path_buf(),
            file,
            lines: session.records.len() + 1,
        };
        Ok((log, session))
    }

    /// Appends `record` as one line and waits until it is on disk.
    pub fn append(&mut self, record: &Record) -> Result<()> {
        let mut line = serde_json::to_string(record)
            .map_err(|e| HilError::serde(format!("{} record", record.kind()), e))?;
        self.append_text(&mut line)
    }

    /// Appends already-serialised text (no newline) and fsyncs.
    pub(crate) fn append_text(&mut self, line: &mut String) -> Result<()> {
        line.push('\n');
        // One write call per line: a kill leaves either the whole line or a
        // prefix without its newline, which `open` discards.
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.sync_data())
            .map_err(|e| HilError::io("writing", &self.path, e))?;
        line.pop();
        self.lines += 1;
        Ok(())
    }

    /// The log's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of lines written so far (including the header).
    pub fn lines(&self) -> usize {
        self.lines
    }
}

/// Makes the new file's directory entry durable too (best effort: not every
/// platform can open a directory).
fn sync_parent_dir(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

fn parse(path: &Path, bytes: &[u8], truncated_bytes: u64) -> Result<LoggedSession> {
    let data_err = |line: usize, field: &str, why: String| HilError::Data {
        path: path.to_path_buf(),
        record: line,
        field: field.to_string(),
        why,
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|b| **b == b'\n')
            .count()
            + 1;
        data_err(line, "record", "the line is not valid UTF-8".into())
    })?;
    let mut header = None;
    let mut records = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let record: Record = serde_json::from_str(raw)
            .map_err(|e| data_err(line, "record", format!("not a valid record: {e}")))?;
        match (&record, line) {
            (Record::Header(h), 1) => {
                if h.format != FORMAT_NAME {
                    return Err(data_err(
                        1,
                        "format",
                        format!("`{}` is not `{FORMAT_NAME}`", h.format),
                    ));
                }
                if h.version != FORMAT_VERSION {
                    let why = if h.version < FORMAT_VERSION {
                        format!(
                            "the log was written in format version {}, which tracked workload \
                             only at query steps; this hil writes version {FORMAT_VERSION}, \
                             which scores WL_T as the paper does, and cannot resume it: \
                             run the session again from its config",
                            h.version
                        )
                    } else {
                        format!(
                            "the log was written in format version {} by a newer hil; this \
                             one reads version {FORMAT_VERSION}",
                            h.version
                        )
                    };
                    return Err(data_err(1, "version", why));
                }
                header = Some(h.clone());
            }
            (Record::Header(_), _) => {
                return Err(data_err(line, "record", "a second header".into()));
            }
            (_, 1) => {
                return Err(data_err(
                    1,
                    "record",
                    format!("expected a header, found `{}`", record.kind()),
                ));
            }
            _ => records.push(LoggedRecord {
                line,
                text: raw.to_string(),
                record,
            }),
        }
    }
    let header = header.ok_or_else(|| {
        data_err(
            1,
            "header",
            "the log has no complete header line: the session never started, so start it again"
                .into(),
        )
    })?;
    Ok(LoggedSession {
        header,
        records,
        truncated_bytes,
    })
}
