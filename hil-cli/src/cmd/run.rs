//! `hil run --config FILE`: run an experiment config.

use std::io::Write;
use std::path::PathBuf;

use hil_core::{ExperimentConfig, HilError, SessionObserver, StepEvent};

/// Arguments of `hil run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The experiment file (TOML).
    #[arg(long, short)]
    pub config: PathBuf,
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
        serde_json::to_writer(&mut self.out, event)
            .map_err(|e| HilError::serde("step event", e))?;
        self.out
            .write_all(b"\n")
            .map_err(|e| HilError::io("writing", &self.path, e))
    }
}

pub fn run(args: RunArgs) -> hil_core::Result<()> {
    let cfg = ExperimentConfig::load(&args.config)?;
    let base = args
        .config
        .parent()
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("."));
    let mut exp = cfg.build(&base)?;
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
    let quiet = args.quiet || args.json;
    let summary = exp.run(&mut observers, |k, r| {
        if !quiet {
            let m = &r.metrics;
            eprintln!(
                "episode {k}: items {} steps {} r_task_avg {:.3} ΔWL {:+.3} f_q {:.3} n_q {} n_success {}",
                m.n_items, m.n_steps, m.r_task_avg, m.delta_wl, m.f_q, m.n_q, m.n_success
            );
        }
    })?;
    if let Some(mut s) = sink {
        s.out
            .flush()
            .map_err(|e| HilError::io("writing", &s.path, e))?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| HilError::serde("summary", e))?
        );
    } else if !args.quiet {
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
