//! One module per subcommand.

use std::path::Path;

pub mod bench;
pub mod data;
#[cfg(feature = "physics")]
pub mod kinova;
// Without MuJoCo, `hil kinova` and `hil demo` only say how to enable them.
#[cfg(not(feature = "physics"))]
#[path = "without_physics.rs"]
pub mod kinova;
pub mod plugins;
pub mod record;
pub mod reproduce;
pub mod run;
pub mod study;
pub mod workload;

/// `--threads`, defined once so that it means the same in every command
/// that runs work in parallel (`hil reproduce`, `hil bench reproduce`,
/// `hil workload select`, `hil kinova calibrate`, `hil demo kinova`): the
/// size of the one job runner, [`hil_jobs::Runner`].
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct Threads {
    /// Worker threads; 0 = one per core (RAYON_NUM_THREADS when set).
    /// Results do not depend on it.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
}

impl Threads {
    /// The runner of this many threads; past
    /// [`hil_jobs::MAX_THREADS`], an error naming `--threads`.
    pub fn runner(self) -> hil_core::Result<hil_jobs::Runner> {
        hil_jobs::Runner::new(self.threads).map_err(|e| as_flag(e, |_| "--threads".into()))
    }
}

/// A library's [`InvalidParameter`](hil_core::HilError::InvalidParameter)
/// error renamed to the flag that set it (`flag(name)`), so the message
/// names what the user typed; other errors pass through.
pub fn as_flag(e: hil_core::HilError, flag: impl FnOnce(&str) -> String) -> hil_core::HilError {
    match e {
        hil_core::HilError::InvalidParameter { name, value, why } => {
            hil_core::HilError::InvalidParameter {
                name: flag(&name),
                value,
                why,
            }
        }
        other => other,
    }
}

/// This run's command line as a person would type it (`hil` and the
/// arguments, shell-quoted where needed), for results pages to name the
/// command that wrote them.
pub fn command_line() -> String {
    let quote = |a: String| {
        let plain = !a.is_empty()
            && a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./=,:+@".contains(c));
        if plain {
            a
        } else {
            format!("'{}'", a.replace('\'', r"'\''"))
        }
    };
    std::iter::once("hil".to_string())
        .chain(
            std::env::args_os()
                .skip(1)
                .map(|a| quote(a.to_string_lossy().into_owned())),
        )
        .collect::<Vec<_>>()
        .join(" ")
}

/// Prints a report and, with `--write-doc FILE`, keeps it as a results
/// page ([`hil_experiments::results_page`]) naming this command line, so
/// that a figure a README cites comes from the command that measured it.
pub fn emit_report(report: &str, write_doc: Option<&Path>, title: &str) -> hil_core::Result<()> {
    crate::out::out!("{report}")?;
    if let Some(path) = write_doc {
        let command = command_line();
        hil_experiments::results_page::ResultsPage {
            title,
            command: &command,
            report,
        }
        .write(path)?;
        crate::out::note!("wrote {}", path.display());
    }
    Ok(())
}
