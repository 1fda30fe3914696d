//! Reading input files with a size limit.
//!
//! Every file hil reads (experiment configs, study CSVs, model JSON, dataset
//! manifests and `.npy` arrays, interaction logs, web assets) goes through
//! [`read_text`] or [`read_bytes`]. Both refuse anything that is not a
//! regular file (a FIFO, `/dev/zero`, a directory) and anything larger than
//! the limit the caller states, *before* reading it, so a wrong path can
//! never grow memory until the process is killed.
//!
//! The limits in [`limits`] are the documented defaults; they are far above
//! any real input of the kind and far below the machine's memory.
//!
//! ```
//! use hil_core::files::{read_text, limits};
//! let dir = std::env::temp_dir().join(format!("hil-files-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("small.toml");
//! std::fs::write(&path, "seed = 1\n").unwrap();
//! assert_eq!(read_text(&path, limits::CONFIG).unwrap(), "seed = 1\n");
//! // Not a regular file: refused with the path in the message.
//! let err = read_text(&dir, limits::CONFIG).unwrap_err();
//! assert!(matches!(err, hil_core::HilError::Io { .. }));
//! ```

use std::io::Read;
use std::path::Path;

use crate::{HilError, Result};

/// Size limits (in bytes) for each kind of input file.
pub mod limits {
    /// Experiment, protocol, benchmark and user-study TOML files.
    pub const CONFIG: u64 = 16 << 20;
    /// Workload-model JSON files.
    pub const MODEL: u64 = 64 << 20;
    /// Study CSV files (TLX surveys and query logs).
    pub const STUDY: u64 = 256 << 20;
    /// Dataset manifests.
    pub const MANIFEST: u64 = 64 << 20;
    /// `.npy` arrays (context features).
    pub const ARRAY: u64 = 1 << 30;
    /// Interaction logs (records of a session).
    pub const LOG: u64 = 1 << 30;
    /// Assets such as item pictures served by the web channel.
    pub const ASSET: u64 = 32 << 20;
}

/// Reads a whole UTF-8 text file of at most `limit` bytes.
///
/// Errors are [`HilError::Io`] naming the path: not a regular file, larger
/// than `limit`, unreadable, or not UTF-8 (`InvalidData`).
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    let bytes = read_bytes(path, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        HilError::io(
            "reading",
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "not UTF-8 text (invalid byte at offset {})",
                    e.utf8_error().valid_up_to()
                ),
            ),
        )
    })
}

/// Writes `text` to `path`, creating its folder first if needed: the one
/// writer of the text outputs commands produce (tables, CSV, SVG).
///
/// Errors are [`HilError::Io`] naming the folder or the file.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| HilError::io("creating", dir, e))?;
    }
    std::fs::write(path, text).map_err(|e| HilError::io("writing", path, e))
}

/// Reads a whole regular file of at most `limit` bytes.
///
/// The file is checked (regular, size) before any byte is read, and the
/// read itself stops at `limit + 1` bytes, so a file that grows while it is
/// read is refused too.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let refuse = |why: String| {
        HilError::io(
            "reading",
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, why),
        )
    };
    // Checked before opening: opening a FIFO for reading would block.
    let meta = std::fs::metadata(path).map_err(|e| HilError::io("reading", path, e))?;
    if !meta.is_file() {
        return Err(refuse(format!(
            "not a regular file ({}); give the path of a file",
            describe_type(&meta)
        )));
    }
    if meta.len() > limit {
        return Err(refuse(too_large(meta.len(), limit)));
    }
    let file = std::fs::File::open(path).map_err(|e| HilError::io("reading", path, e))?;
    let mut out = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut out)
        .map_err(|e| HilError::io("reading", path, e))?;
    if out.len() as u64 > limit {
        return Err(refuse(format!(
            "grew past the limit while being read; {}",
            too_large(out.len() as u64, limit)
        )));
    }
    Ok(out)
}

fn too_large(len: u64, limit: u64) -> String {
    format!("{len} bytes is more than this kind of file may hold ({limit} bytes)")
}

fn describe_type(meta: &std::fs::Metadata) -> &'static str {
    let ft = meta.file_type();
    if ft.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_char_device() {
            return "a character device";
        }
        if ft.is_block_device() {
            return "a block device";
        }
        if ft.is_fifo() {
            return "a FIFO";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    "not a file"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hil-files-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn refuses_devices_and_directories_before_reading() {
        for p in ["/dev/zero", "/dev/urandom"] {
            let err = read_bytes(Path::new(p), limits::CONFIG).unwrap_err();
            match err {
                HilError::Io { path, source, .. } => {
                    assert_eq!(path, Path::new(p));
                    assert_eq!(source.kind(), std::io::ErrorKind::InvalidInput);
                }
                other => panic!("{other:?}"),
            }
        }
        assert!(matches!(
            read_text(&tmp("dir"), limits::CONFIG),
            Err(HilError::Io { .. })
        ));
    }

    #[test]
    fn refuses_files_over_the_limit_and_reads_files_at_it() {
        let dir = tmp("limit");
        let p = dir.join("f");
        std::fs::write(&p, vec![b'a'; 100]).unwrap();
        assert_eq!(read_bytes(&p, 100).unwrap().len(), 100);
        match read_bytes(&p, 99).unwrap_err() {
            HilError::Io { source, .. } => {
                assert_eq!(source.kind(), std::io::ErrorKind::InvalidInput)
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn non_utf8_text_is_invalid_data() {
        let dir = tmp("utf8");
        let p = dir.join("f");
        std::fs::write(&p, [b'o', b'k', 0xff]).unwrap();
        match read_text(&p, 10).unwrap_err() {
            HilError::Io { source, .. } => {
                assert_eq!(source.kind(), std::io::ErrorKind::InvalidData)
            }
            other => panic!("{other:?}"),
        }
    }
}
