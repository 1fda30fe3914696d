//! `hil run --config FILE [--log LOG]`: run an experiment config, recording
//! every step; `hil run --resume LOG`: continue a recorded session.

use std::io::Write;
use std::path::{Path, PathBuf};

use hil_core::record::{Header, RecordLog};
use hil_core::{EpisodeMetrics, HilError, SessionObserver, StepEvent};
use hil_experiments::ExperimentSummary;
use hil_experiments::run_recorded;

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

/// Writes step events as JSON lines.
struct JsonlEvents {
    path: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
}

impl SessionObserver for JsonlEvents {
    fn on_step(&mut self, event: &StepEvent) -> hil_core::Result<()> {
        // Serialised apart from writing, so that a failing file (a full
        // disk, /dev/full) is reported as an I/O error naming it.
        let mut line = serde_json::to_vec(event).map_err(|e| HilError::serde("step event", e))?;
        line.push(b'\n');
        self.out
            .write_all(&line)
            .map_err(|e| HilError::io("writing", &self.path, e))
    }
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
    // destructor panicked is reported (PLUGINS.md), not passed over. The
    // first error is returned (and printed by `main`); any others are
    // printed here.
    let mut errors = result
        .err()
        .into_iter()
        .chain(hil_plugin::take_destructor_panics());
    let Some(first) = errors.next() else {
        return Ok(());
    };
    for e in errors {
        eprintln!("error: {e}");
    }
    Err(first)
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
    let mut sink = match &args.events {
        Some(p) => Some(JsonlEvents {
            path: p.clone(),
            out: std::io::BufWriter::new(
                std::fs::File::create(p).map_err(|e| HilError::io("creating", p, e))?,
            ),
        }),
        None => None,
    };
    let mut observers: Vec<&mut dyn SessionObserver> = Vec::new();
    if let Some(s) = sink.as_mut() {
        observers.push(s);
    }
    let progress = |k: usize, m: &EpisodeMetrics| {
        if !quiet {
            eprintln!(
                "episode {k}: items {} steps {} r_task_avg {:.3} ΔWL {:+.3} f_q {:.3} n_q {} n_success {}",
                m.n_items, m.n_steps, m.r_task_avg, m.delta_wl, m.f_q, m.n_q, m.n_success
            );
        }
    };

    install_interrupt_notice(match &start {
        Start::Fresh { log, .. } => log.clone(),
        Start::Resume(log) => Some(log.clone()),
    });
    let summary = match start {
        Start::Fresh { config, log } => {
            let text = hil_core::files::read_text(&config, hil_core::files::limits::CONFIG)?;
            let cfg = hil_experiments::parse_experiment(&text, &config)?;
            // Absolute, so that a resume from another directory finds the
            // same files; made absolute before taking the directory, which
            // for a bare file name (`exp.toml`) is empty.
            let config_abs = absolute(&config)?;
            let base = config_abs
                .parent()
                .map_or_else(|| config_abs.clone(), Path::to_path_buf);
            let mut exp = cfg.build(&base)?;
            announce_endpoint(exp.channel.endpoint());
            match log {
                Some(log_path) => {
                    let header = Header::new(&text, config_abs, base, exp.seed, exp.episodes);
                    let log = RecordLog::create(&log_path, header)?;
                    if !quiet {
                        eprintln!("recording to {}", log_path.display());
                    }
                    run_recorded(&mut exp, log, None, &mut observers, progress)?
                }
                None => exp.run(&mut observers, |k, r| progress(k, &r.metrics))?,
            }
        }
        Start::Resume(log_path) => {
            let (log, logged) = RecordLog::open(&log_path)?;
            let header = &logged.header;
            let cfg = hil_experiments::parse_experiment(&header.config, &header.config_path)?;
            let mut exp = cfg.build(&header.base_dir)?;
            if !quiet {
                eprintln!(
                    "resuming {} ({} records{})",
                    log_path.display(),
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
            announce_endpoint(exp.channel.endpoint());
            run_recorded(&mut exp, log, Some(&logged), &mut observers, progress)?
        }
    };
    drop(observers);
    if let Some(mut s) = sink {
        s.out
            .flush()
            .map_err(|e| HilError::io("writing", &s.path, e))?;
    }
    Ok(summary)
}

/// On Ctrl-C (or SIGTERM), says what was kept and how to continue, then
/// exits with status 130. Every step answered so far is already on disk
/// (steps are fsync'ed before the robot acts); a line cut short by the
/// interrupt is discarded by `--resume`.
#[cfg(unix)]
fn install_interrupt_notice(log: Option<PathBuf>) {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return; // the default behaviour (ending the process) still applies
    };
    let _ = std::thread::Builder::new()
        .name("hil-interrupt".into())
        .spawn(move || {
            if signals.forever().next().is_some() {
                match &log {
                    Some(p) => eprintln!(
                        "\ninterrupted: every answered step is in {0}; continue with `hil run --resume {0}`",
                        p.display()
                    ),
                    None => eprintln!(
                        "\ninterrupted: no interaction log was kept (run with --log LOG to be able to resume)"
                    ),
                }
                std::process::exit(130);
            }
        });
}

#[cfg(not(unix))]
fn install_interrupt_notice(_log: Option<PathBuf>) {}

/// Tells the researcher where the person answers (a web channel's URL).
/// Printed even with --quiet: without it nobody can answer.
fn announce_endpoint(endpoint: Option<String>) {
    if let Some(urls) = endpoint {
        eprintln!("open this address on the phone or tablet to answer the robot's questions:");
        // One line per address (a web page bound to 0.0.0.0 has several).
        for url in urls.lines() {
            eprintln!("  {url}");
        }
    }
}

fn absolute(path: &Path) -> hil_core::Result<PathBuf> {
    std::path::absolute(path).map_err(|e| HilError::io("resolving", path, e))
}

fn print_summary(summary: &ExperimentSummary, json: bool, quiet: bool) -> hil_core::Result<()> {
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(summary).map_err(|e| HilError::serde("summary", e))?
        );
    } else if !quiet {
        println!(
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
        );
    }
    Ok(())
}
