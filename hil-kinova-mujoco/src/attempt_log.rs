//! The attempt log of a calibration: one JSON object per simulated attempt
//! (food, setting, trial, seed and what the simulation measured), one per
//! line.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use hil_core::{HilError, Result};

use crate::calibrate::AttemptRecord;

/// A JSON-lines file of [`AttemptRecord`]s. Created before a run, so that
/// a path that cannot be written fails before any simulation time is spent.
#[derive(Debug)]
pub struct AttemptLog {
    path: PathBuf,
    file: File,
}

impl AttemptLog {
    /// Creates (or truncates) the file at `path`.
    pub fn create(path: &Path) -> Result<Self> {
        let file = File::create(path).map_err(|e| HilError::io("create", path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Writes `records`, one JSON line each, and closes the file.
    pub fn write(self, records: &[AttemptRecord]) -> Result<()> {
        let mut w = BufWriter::new(self.file);
        for r in records {
            let line = serde_json::to_string(r).map_err(|e| HilError::serde("attempt", e))?;
            writeln!(w, "{line}").map_err(|e| HilError::io("write", &self.path, e))?;
        }
        w.flush().map_err(|e| HilError::io("write", &self.path, e))
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
