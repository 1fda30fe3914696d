//! `hil run --config FILE [--log LOG]`: run an experiment config, recording
//! every step; `hil run --resume LOG`: continue a recorded session.

use crate::out::{note, outln};
use std::path::{Path, PathBuf};

use hil_core::{EpisodeMetrics, HilError, SessionObserver};
use hil_experiments::ExperimentSummary;
use hil_experiments::run::{JsonlEvents, Recording, Run};

/// Arguments of `hil run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The experiment file (TOML).
    #[arg(long, short, required_unless_present = "resume")]
    pub config: Option<PathBuf>,
    /// Record every step in this interaction log (JSONL; each step is on
    /// disk before the robot acts). The file must not exist yet.
    #[arg(long, value_name = "LOG")]
    pub log: Option<PathBuf>,
    /// Continue the session recorded in LOG (after a crash, a kill or an
    /// interrupt): the config comes from the log, answered queries are not
    /// asked again, and new steps are appended to LOG. A log has one
    /// writer: this is refused, naming the process, while another hil
    /// writes LOG; and a log changed since it was written is refused with
    /// the line at fault.
    #[arg(long, value_name = "LOG", conflicts_with_all = ["config", "log"])]
    pub resume: Option<PathBuf>,
    /// Key the interaction log with the secret key in FILE (made by `hil
    /// record keygen`; refused if its group or others may read it): every
    /// line is chained with HMAC-SHA256, so an edited log cannot be
    /// re-chained without the key. With --resume, the key of a keyed log
    /// (required for one). Keep FILE outside the log's folder.
    #[arg(long, value_name = "FILE")]
    pub record_key: Option<PathBuf>,
    /// Write every step event to this JSONL file.
    #[arg(long)]
    pub events: Option<PathBuf>,
    /// Print the summary as JSON on stdout instead of text.
    #[arg(long)]
    pub json: bool,
    /// Print nothing but errors (and the JSON summary with --json).
    #[arg(long, short)]
    pub quiet: bool,
}

/// The session to run: a fresh one from a config, or a logged one to resume.
enum Start {
    Fresh {
        config: PathBuf,
        log: Option<PathBuf>,
    },
    Resume(PathBuf),
}

pub fn run(args: RunArgs) -> hil_core::Result<()> {
    let result = run_session(&args).and_then(|s| print_summary(&s, args.json, args.quiet));
    // Every component has been dropped by now: a plugin object whose
    // destructor panicked is reported (PLUGINS.md), not passed over.
    super::plugins::with_destructor_panics(result)
}

/// Runs (or resumes) the session `args` describe; every component is
/// dropped before this returns.
fn run_session(args: &RunArgs) -> hil_core::Result<ExperimentSummary> {
    let start = match (&args.resume, &args.config) {
        (Some(log), _) => Start::Resume(log.clone()),
        (None, Some(config)) => Start::Fresh {
            config: config.clone(),
            log: args.log.clone(),
        },
        (None, None) => {
            return Err(HilError::invalid_input(
                "arguments",
                "give --config FILE, or --resume LOG",
            ));
        }
    };
    let quiet = args.quiet || args.json;
    let mut sink = args
        .events
        .as_deref()
        .map(JsonlEvents::create)
        .transpose()?;
    let mut observers: Vec<&mut dyn SessionObserver> = Vec::new();
    if let Some(s) = sink.as_mut() {
        observers.push(s);
    }
    let progress = |k: usize, m: &EpisodeMetrics| {
        if !quiet {
            note!(
                "episode {k}: items {} steps {} r_task_avg {:.3} ΔWL {:+.3} f_q {:.3} n_q {} n_success {}",
                m.n_items,
                m.n_steps,
                m.r_task_avg,
                m.delta_wl,
                m.f_q,
                m.n_q,
                m.n_success
            );
        }
    };

    install_interrupt_notice(
        match &start {
            Start::Fresh { log, .. } => log.clone(),
            Start::Resume(log) => Some(log.clone()),
        },
        args.record_key.clone(),
    );
    let key = args
        .record_key
        .as_deref()
        .map(hil_record::RecordKey::read)
        .transpose()?;
    let run = match &start {
        Start::Fresh { config, log } => Run::from_config_with_key(config, log.as_deref(), key)?,
        Start::Resume(log) => Run::resume_with_key(log, key)?,
    };
    if !quiet && let Some(logged) = run.recording.logged() {
        note!(
            "resuming {} ({} records{})",
            run.recording.path().unwrap_or(Path::new("")).display(),
            logged.records.len() + 1,
            if logged.truncated_bytes > 0 {
                format!(
                    "; discarded an incomplete last line of {} bytes",
                    logged.truncated_bytes
                )
            } else {
                String::new()
            }
        );
    }
    announce_endpoint(run.experiment.channel.endpoint());
    if !quiet && let Recording::New(log) = &run.recording {
        note!("recording to {}", log.path().display());
    }
    let summary = run.execute(&mut observers, progress)?;
    drop(observers);
    if let Some(s) = sink {
        s.finish()?;
    }
    Ok(summary)
}

/// On Ctrl-C (or SIGTERM), says what was kept and how to continue, then
/// exits with status 130. Every step answered so far is already on disk
/// (steps are fsync'ed before the robot acts); a line cut short by the
/// interrupt is discarded by `--resume`. A session answering by voice is
/// stopped between utterances instead (`hil_speech::stop`): the answer
/// being spoken is heard and kept, then the channel ends the session; a
/// second Ctrl-C exits at once.
#[cfg(unix)]
fn install_interrupt_notice(log: Option<PathBuf>, key: Option<PathBuf>) {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return; // the default behaviour (ending the process) still applies
    };
    let _ = std::thread::Builder::new()
        .name("hil-interrupt".into())
        .spawn(move || {
            if signals.forever().next().is_some() {
                match &log {
                    Some(p) => note!(
                        "\ninterrupted: every answered step is in {0}; continue with `hil run --resume {0}{1}`",
                        p.display(),
                        key.as_ref()
                            .map(|k| format!(" --record-key {}", k.display()))
                            .unwrap_or_default()
                    ),
                    None => note!(
                        "\ninterrupted: no interaction log was kept (run with --log LOG to be able to resume)"
                    ),
                }
                if stop_spoken_channels() > 0 {
                    note!("stopping after the answer being spoken (Ctrl-C again to quit now)");
                    if signals.forever().next().is_none() {
                        return;
                    }
                }
                std::process::exit(130);
            }
        });
}

/// Raises the stop flag of every live spoken channel; how many there were
/// (none in a build without `speech`).
#[cfg(unix)]
fn stop_spoken_channels() -> usize {
    #[cfg(feature = "speech")]
    return hil_speech::stop::stop_all();
    #[cfg(not(feature = "speech"))]
    0
}

#[cfg(not(unix))]
fn install_interrupt_notice(_log: Option<PathBuf>, _key: Option<PathBuf>) {}

/// Tells the researcher where the person answers (a web channel's URL).
/// Printed even with --quiet: without it nobody can answer.
fn announce_endpoint(endpoint: Option<String>) {
    if let Some(urls) = endpoint {
        note!("open this address on the phone or tablet to answer the robot's questions:");
        // One line per address (a web page bound to 0.0.0.0 has several).
        for url in urls.lines() {
            note!("  {url}");
        }
    }
}

fn print_summary(summary: &ExperimentSummary, json: bool, quiet: bool) -> hil_core::Result<()> {
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(summary).map_err(|e| HilError::serde("summary", e))?
        )?;
    } else if !quiet {
        outln!(
            "{} episode(s): r_task_avg {:.3} ± {:.3}, ΔWL {:+.3} ± {:.3}, f_q {:.3} ± {:.3}, t_conv {:.2} ± {:.2}",
            summary.episodes.len(),
            summary.r_task_avg.0,
            summary.r_task_avg.1,
            summary.delta_wl.0,
            summary.delta_wl.1,
            summary.f_q.0,
            summary.f_q.1,
            summary.t_conv.0,
            summary.t_conv.1,
        )?;
    }
    Ok(())
}
