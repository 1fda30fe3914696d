//! The log file: durable, chained appends by its one writer, and reading
//! back with a torn last line detected and discarded and every complete
//! line verified.

use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::chain::{self, Chain};
use crate::format::{FORMAT_NAME, FORMAT_VERSION, Header, Record};
use crate::key::RecordKey;
use crate::lock;
use hil_core::error::{HilError, Result};
use hil_core::files::{limits, read_bytes};

/// An append-only JSONL file whose every line reaches the disk (fsync)
/// before [`RecordLog::append`] returns.
///
/// A `RecordLog` is the log's only writer: creating or opening one takes an
/// exclusive lock on the file (see [`super::lock`]), held until it is
/// dropped, so a second writer (another `hil run --resume`, or a resume
/// while the original run is still going) is refused with an
/// [`HilError::Io`] of kind `WouldBlock` that names the holder.
#[derive(Debug)]
pub struct RecordLog {
    path: PathBuf,
    file: File,
    lines: usize,
    chain: Chain,
}

/// A logged record with its line number (1-based) and exact content.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedRecord {
    /// 1-based line number.
    pub line: usize,
    /// The record's JSON as written: the line without its newline and
    /// without its `chain` field (which depends on the lines before it).
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
    /// Creates a new log at `path` starting with `header`, and locks it.
    /// Refuses to overwrite an existing file (it may hold a session to
    /// resume).
    pub fn create(path: &Path, header: Header) -> Result<Self> {
        Self::create_with_key(path, header, None)
    }

    /// [`RecordLog::create`], keyed with `key` if given: the header records
    /// the key's id and every line is chained with HMAC-SHA256
    /// ([`super::key`]).
    pub fn create_with_key(
        path: &Path,
        mut header: Header,
        key: Option<RecordKey>,
    ) -> Result<Self> {
        header.record_key = key.as_ref().map(RecordKey::id);
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|e| HilError::io("creating", path, e))?;
        sync_parent_dir(path);
        let mut log = Self::locked(path, file)?;
        if let Some(key) = key {
            log.chain = Chain::start_keyed(key);
        }
        log.append(&Record::Header(header))?;
        Ok(log)
    }

    /// Opens an existing log for resuming: locks it, reads it (at most
    /// [`limits::LOG`] bytes, a regular file only), verifies every complete
    /// line (its record and its place in the hash chain), cuts off an
    /// incomplete last line (a write the process did not finish, so the
    /// robot never acted on it) and positions for appending.
    ///
    /// Every error names the file, and where a line is at fault, the line
    /// and field ([`HilError::Data`]). A keyed log is refused (at line 1,
    /// field `record_key`): open it with [`RecordLog::open_with_key`].
    pub fn open(path: &Path) -> Result<(Self, LoggedSession)> {
        Self::open_with_key(path, None)
    }

    /// [`RecordLog::open`] with the log's key, if it is keyed. A key for an
    /// unkeyed log, or one whose id is not the header's, is refused at
    /// line 1 (field `record_key`); a line whose HMAC does not verify, at
    /// that line (field `chain`).
    pub fn open_with_key(path: &Path, key: Option<RecordKey>) -> Result<(Self, LoggedSession)> {
        // Opening for writing never blocks (not even on a FIFO); anything
        // that is not a regular file is then refused by `read_bytes`.
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| HilError::io("opening", path, e))?;
        // Locked before reading, so that nobody appends while we read.
        let mut log = Self::locked(path, file)?;
        let bytes = read_bytes(path, limits::LOG)?;
        let complete = bytes.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1);
        let truncated_bytes = (bytes.len() - complete) as u64;
        let (session, chain) = parse(path, &bytes[..complete], truncated_bytes, key)?;
        if truncated_bytes > 0 {
            log.file
                .set_len(complete as u64)
                .and_then(|()| log.file.sync_data())
                .map_err(|e| HilError::io("truncating", path, e))?;
        }
        log.file
            .seek(SeekFrom::End(0))
            .map_err(|e| HilError::io("seeking in", path, e))?;
        log.lines = session.records.len() + 1;
        log.chain = chain;
        Ok((log, session))
    }

    /// Reads and verifies the log at `path` as [`RecordLog::open_with_key`]
    /// does, without taking its lock or changing it (an incomplete last
    /// line is reported in `truncated_bytes`, not cut off): what
    /// `hil record verify` runs.
    pub fn verify(path: &Path, key: Option<RecordKey>) -> Result<LoggedSession> {
        let bytes = read_bytes(path, limits::LOG)?;
        let complete = bytes.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1);
        let truncated_bytes = (bytes.len() - complete) as u64;
        Ok(parse(path, &bytes[..complete], truncated_bytes, key)?.0)
    }

    /// Locks `file` (the log at `path`) and records this process as its
    /// owner.
    fn locked(path: &Path, file: File) -> Result<Self> {
        lock::lock(&file, path)?;
        // From here on, dropping the log removes the owner file.
        let log = Self {
            path: path.to_path_buf(),
            file,
            lines: 0,
            chain: Chain::start(),
        };
        lock::claim(path)?;
        Ok(log)
    }

    /// Appends `record` as one line and waits until it is on disk.
    pub fn append(&mut self, record: &Record) -> Result<()> {
        let content = serde_json::to_string(record)
            .map_err(|e| HilError::serde(format!("{} record", record.kind()), e))?;
        self.write_line(&content, !matches!(record, Record::Resumed { .. }))
    }

    /// Appends an already-serialised record (not a `resumed` marker) and
    /// fsyncs.
    pub(crate) fn append_text(&mut self, content: &str) -> Result<()> {
        self.write_line(content, true)
    }

    fn write_line(&mut self, content: &str, advance: bool) -> Result<()> {
        let mut chain = self.chain.clone();
        let mut line = chain.seal(content, advance);
        line.push('\n');
        // One write call per line: a kill leaves either the whole line or a
        // prefix without its newline, which `open` discards.
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.sync_data())
            .map_err(|e| HilError::io("writing", &self.path, e))?;
        // Only a line that reached the file moves the chain on.
        self.chain = chain;
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

impl Drop for RecordLog {
    fn drop(&mut self) {
        // While the lock is still held (the file closes after this).
        lock::release(&self.path);
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

/// What the first line of any version of the format says about itself.
#[derive(Deserialize)]
struct VersionProbe {
    record: Option<String>,
    format: Option<String>,
    version: Option<u32>,
}

/// Refuses a first line that is not a header of this format and version,
/// before anything else about the log is trusted.
fn check_version(raw: &str) -> std::result::Result<(), (&'static str, String)> {
    let probe: VersionProbe =
        serde_json::from_str(raw).map_err(|e| ("record", format!("not a valid record: {e}")))?;
    match probe.record.as_deref() {
        Some("header") => {}
        Some(kind) => return Err(("record", format!("expected a header, found `{kind}`"))),
        None => {
            return Err((
                "record",
                "expected a header, found no `record` field".into(),
            ));
        }
    }
    let format = probe.format.unwrap_or_default();
    if format != FORMAT_NAME {
        return Err(("format", format!("`{format}` is not `{FORMAT_NAME}`")));
    }
    let version = probe.version.unwrap_or(0);
    let why = match version {
        FORMAT_VERSION => return Ok(()),
        1 => format!(
            "the log was written in format version 1, which tracked workload only at query \
             steps; this hil writes version {FORMAT_VERSION}, which scores WL_T as the paper \
             does, and cannot resume it: run the session again from its config"
        ),
        v if v < FORMAT_VERSION => format!(
            "the log was written in format version {v}, whose lines carry no hash chain, so \
             this hil (version {FORMAT_VERSION}) cannot check that it is unchanged and will not \
             resume it: run the session again from its config"
        ),
        v => format!(
            "the log was written in format version {v} by a newer hil; this one reads version \
             {FORMAT_VERSION}"
        ),
    };
    Err(("version", why))
}

/// The chain a log with header `h` is verified with, given the key the
/// reader holds: refused unless both or neither say the log is keyed, and
/// with the same key.
fn start_chain(h: &Header, key: Option<RecordKey>) -> std::result::Result<Chain, String> {
    match (&h.record_key, key) {
        (None, None) => Ok(Chain::start()),
        (Some(id), None) => Err(format!(
            "the log is keyed (key id {id}): it verifies only with its key \
             (`--record-key FILE` / `--key FILE`)"
        )),
        (None, Some(key)) => Err(format!(
            "a key was given ({}) but the log is not keyed: it was written without a key, or a \
             keyed log was re-chained without one",
            key.path().display()
        )),
        (Some(id), Some(key)) if *id != key.id() => Err(format!(
            "the log was keyed with key id {id}, but the key in {} has id {}: the wrong key, \
             or the header was changed",
            key.path().display(),
            key.id()
        )),
        (Some(_), Some(key)) => Ok(Chain::start_keyed(key)),
    }
}

/// Parses and verifies the complete lines of a log; returns what it holds
/// and the chain value after its last line.
fn parse(
    path: &Path,
    bytes: &[u8],
    truncated_bytes: u64,
    mut key: Option<RecordKey>,
) -> Result<(LoggedSession, Chain)> {
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
    let mut chain = Chain::start();
    for (i, raw) in text.split_terminator('\n').enumerate() {
        let line = i + 1;
        if line == 1 {
            check_version(raw).map_err(|(field, why)| data_err(1, field, why))?;
        }
        let (digest, content) = chain::split(raw).ok_or_else(|| {
            data_err(
                line,
                chain::FIELD,
                format!(
                    "the line does not start with its `{}` digest (64 hex digits): it was not \
                     written by hil, or was edited",
                    chain::FIELD
                ),
            )
        })?;
        let record: Record = serde_json::from_str(&content)
            .map_err(|e| data_err(line, "record", format!("not a valid record: {e}")))?;
        // Checked first, as the more precise of the two complaints.
        if let Record::Header(h) = &record
            && h.config_digest != chain::digest_hex(&h.config)
        {
            return Err(data_err(
                line,
                "config_digest",
                "the header's config is not the one the session started with (its SHA-256 \
                 differs from `config_digest`)"
                    .into(),
            ));
        }
        if let Record::Header(h) = &record
            && line == 1
        {
            chain = start_chain(h, key.take()).map_err(|why| data_err(1, "record_key", why))?;
        }
        chain
            .check(digest, &content, !matches!(record, Record::Resumed { .. }))
            .map_err(|why| data_err(line, chain::FIELD, why))?;
        match (record, line) {
            (Record::Header(h), 1) => header = Some(h),
            (Record::Header(_), _) => {
                return Err(data_err(line, "record", "a second header".into()));
            }
            (record, _) => records.push(LoggedRecord {
                line,
                text: content,
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
    Ok((
        LoggedSession {
            header,
            records,
            truncated_bytes,
        },
        chain,
    ))
}
