//! Writing to standard output and standard error without panicking.
//!
//! Rust ignores SIGPIPE, so a write to a pipe whose reader has gone (`hil
//! data check DIR | head -3`) fails with `BrokenPipe`, and `println!` turns
//! that failure into a panic (exit 101). Every command prints through this
//! module instead:
//!
//! - [`outln!`] / [`out!`] write to stdout and return the failure as an
//!   error naming [`STDOUT`]; `main` ends the program quietly on a closed
//!   stdout with [`CLOSED_STDOUT_STATUS`], the status a shell reports for a
//!   program ended by SIGPIPE.
//! - [`note!`] writes a line to stderr and ignores failure: a progress line
//!   or a notice that cannot be shown must never stop the program (nor keep
//!   it from stopping: the Ctrl-C/SIGTERM handler of `hil run` prints
//!   through it before it exits).

use std::fmt;
use std::io::{self, Write};
use std::path::Path;

use hil_core::HilError;

/// The name [`HilError::Io`] gives standard output.
pub const STDOUT: &str = "<standard output>";

/// Exit status on a closed stdout: 128 + SIGPIPE (13), as a shell reports
/// for a program that SIGPIPE ended (`yes | head -1`).
pub const CLOSED_STDOUT_STATUS: u8 = 128 + 13;

/// Writes `args` to stdout (flushed, so a closed pipe is seen here and not
/// at exit).
pub fn stdout(args: fmt::Arguments<'_>) -> hil_core::Result<()> {
    let mut out = io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|source| HilError::Io {
            op: "writing",
            path: STDOUT.into(),
            source,
        })
}

/// Writes `args` to stderr, ignoring failure (see the module doc).
pub fn stderr(args: fmt::Arguments<'_>) {
    let _ = io::stderr().lock().write_fmt(args);
}

/// Whether `e` is a write to a stdout whose reader has gone.
pub fn is_closed_stdout(e: &HilError) -> bool {
    matches!(e, HilError::Io { path, source, .. }
        if path == Path::new(STDOUT) && source.kind() == io::ErrorKind::BrokenPipe)
}

/// `println!` that returns an error instead of panicking (use with `?`).
macro_rules! outln {
    () => {
        $crate::out::stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that returns an error instead of panicking (use with `?`).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::out::stdout(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics: a line that cannot be written is dropped.
macro_rules! note {
    () => {
        $crate::out::stderr(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {note, out, outln};
