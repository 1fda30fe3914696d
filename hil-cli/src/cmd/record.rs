//! `hil record keygen FILE` and `hil record verify LOG [--key FILE]`: the
//! secret key of a keyed interaction log, and checking a log's chain
//! without resuming it.

use std::path::PathBuf;

use hil_record::{RecordKey, RecordLog};

use crate::out::outln;

/// Arguments of `hil record`.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    #[command(subcommand)]
    pub command: RecordCommand,
}

/// `hil record` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum RecordCommand {
    /// Write a new random key for keyed logs (`hil run --record-key FILE`):
    /// 32 bytes from the operating system, as hex, readable by its owner
    /// only (mode 0600). Keep it outside the folder the logs are shared
    /// from: whoever holds it can forge a log that verifies.
    Keygen(KeygenArgs),
    /// Check an interaction log's hash chain without resuming or changing
    /// it: every line, and for a keyed log that KEY is its key. (Resuming
    /// also replays the session and checks it against the log.)
    Verify(VerifyArgs),
}

/// Arguments of `hil record keygen`.
#[derive(Debug, clap::Args)]
pub struct KeygenArgs {
    /// Where to write the key (must not exist yet).
    pub file: PathBuf,
}

/// Arguments of `hil record verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// The interaction log.
    pub log: PathBuf,
    /// The log's key, if it is keyed (the file `hil record keygen` wrote).
    #[arg(long, value_name = "FILE")]
    pub key: Option<PathBuf>,
}

pub fn run(args: RecordArgs) -> hil_core::Result<()> {
    match args.command {
        RecordCommand::Keygen(a) => {
            let key = RecordKey::generate(&a.file)?;
            outln!("wrote {} (key id {})", a.file.display(), key.id())
        }
        RecordCommand::Verify(a) => {
            let key = a.key.as_deref().map(RecordKey::read).transpose()?;
            let how = match &key {
                Some(k) => format!(
                    "keyed: every line's HMAC-SHA256 verifies with the key in {} (key id {})",
                    k.path().display(),
                    k.id()
                ),
                None => "unkeyed: no damage, and no edit that left the SHA-256 chain \
                         unrecomputed (an unkeyed chain cannot show forgery)"
                    .into(),
            };
            let logged = RecordLog::verify(&a.log, key)?;
            outln!(
                "{}: {} complete line(s) verified; {how}",
                a.log.display(),
                logged.records.len() + 1
            )?;
            if logged.truncated_bytes > 0 {
                outln!(
                    "{}: an incomplete last line of {} bytes (a write cut short), which \
                     `hil run --resume` discards",
                    a.log.display(),
                    logged.truncated_bytes
                )?;
            }
            Ok(())
        }
    }
}
