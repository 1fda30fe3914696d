//! One writer per log: an exclusive lock on the log file, held while its
//! [`super::RecordLog`] lives, and a small owner file that says who holds it.
//!
//! The lock is the operating system's advisory file lock on the log itself
//! (`flock` on Unix), so it ends with the process however the process ends
//! (even `kill -9`) and never goes stale. The owner file next to the log
//! (`LOG.owner`: process id, host, start time) is only read to explain a
//! refusal; it is removed when the writer closes the log.

use std::fs::{File, TryLockError};
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use hil_core::error::{HilError, Result};
use hil_core::files::{limits, read_text};

/// Who holds a log: written to its owner file by the writer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Owner {
    /// Process id.
    pub pid: u32,
    /// Host name (`unknown host` where it cannot be found).
    pub host: String,
    /// When the writer took the lock, in seconds since the Unix epoch.
    pub since_unix_s: u64,
}

impl Owner {
    fn this_process() -> Self {
        Self {
            pid: std::process::id(),
            host: host_name(),
            since_unix_s: now_unix_s(),
        }
    }
}

impl std::fmt::Display for Owner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ago = now_unix_s().saturating_sub(self.since_unix_s);
        write!(
            f,
            "process {} on {}, since Unix time {} ({ago} s ago)",
            self.pid, self.host, self.since_unix_s
        )
    }
}

/// The owner file of the log at `log`.
pub fn owner_path(log: &Path) -> PathBuf {
    let mut name = log.as_os_str().to_owned();
    name.push(".owner");
    PathBuf::from(name)
}

/// Takes the exclusive lock on `file` (the open log at `path`) without
/// waiting. If another writer holds it, the error is an
/// [`HilError::Io`] of kind `WouldBlock` naming the log and the holder.
pub(crate) fn lock(file: &File, path: &Path) -> Result<()> {
    // `File::try_lock` is stable since Rust 1.89. The workspace still
    // declares 1.85, which is already stale: let chains, used throughout,
    // need 1.88.
    #[allow(clippy::incompatible_msrv)]
    let locked = file.try_lock();
    match locked {
        Ok(()) => Ok(()),
        Err(TryLockError::WouldBlock) => Err(HilError::io(
            "locking",
            path,
            std::io::Error::new(
                std::io::ErrorKind::WouldBlock,
                format!(
                    "another hil is writing this log: {}. A log has one writer: wait until \
                     it ends (or stop it), then resume",
                    holder(path)
                ),
            ),
        )),
        Err(TryLockError::Error(e)) => Err(HilError::io("locking", path, e)),
    }
}

/// Records this process as the owner of the log at `path` (call with the
/// lock held).
pub(crate) fn claim(path: &Path) -> Result<()> {
    let owner = owner_path(path);
    let text = serde_json::to_string(&Owner::this_process())
        .map_err(|e| HilError::serde("log owner", e))?;
    std::fs::write(&owner, text + "\n").map_err(|e| HilError::io("writing", &owner, e))
}

/// Removes the owner file (call with the lock still held, so that the next
/// writer's file is never the one removed).
pub(crate) fn release(path: &Path) {
    // Best effort: a stale owner file is only ever read to explain a
    // refusal while the lock is held, and the next writer overwrites it.
    let _ = std::fs::remove_file(owner_path(path));
}

/// Who holds the lock on `path`, as far as its owner file says.
fn holder(path: &Path) -> String {
    let owner = owner_path(path);
    match read_text(&owner, limits::CONFIG) {
        Ok(text) => match serde_json::from_str::<Owner>(&text) {
            Ok(o) => format!("held by {o}"),
            Err(e) => format!("its owner file {} is unreadable: {e}", owner.display()),
        },
        Err(e) => format!("the holder has not written its owner file yet: {e}"),
    }
}

fn now_unix_s() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

fn host_name() -> String {
    // Linux exposes it as a file; elsewhere the environment may carry it.
    read_text(Path::new("/proc/sys/kernel/hostname"), limits::CONFIG)
        .ok()
        .map(|s| s.trim().to_string())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .or_else(|| std::env::var("COMPUTERNAME").ok())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown host".into())
}
