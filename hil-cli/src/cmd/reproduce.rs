//! `hil reproduce`: rerun every simulated experiment of the paper.
//!
//! Argument handling only: the protocol, its aggregation, tables and figures
//! are `hil_experiments`; the methods are policy configs (built-in or plugin
//! types) listed in the protocol settings; the workload models are
//! hil-workload's bundled simulation models.

use crate::out::{note, outln};
use std::path::PathBuf;
use std::time::Instant;

use hil_core::HilError;
use hil_experiments::output::{Timing, Written, report};
use hil_experiments::{Protocol, ProtocolSettings};

/// Arguments of `hil reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Smaller hyperparameter grids and 2 policy seeds (a smoke run).
    #[arg(long)]
    pub quick: bool,
    /// Output directory (results.json, tables.md, SVG figures).
    #[arg(long, short, default_value = "reproduce-out")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Protocol settings file (TOML, every field of `ProtocolSettings`:
    /// methods as policy configs, grids, seeds, split, figures; `plugins`
    /// it lists are loaded first), instead of the paper's (or --quick) settings.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// A food dataset directory instead of the settings' (default: the
    /// bundled synthetic one).
    #[arg(long)]
    pub dataset: Option<PathBuf>,
    /// Environment seeds of the many-seed run beside the paper's 3-seed
    /// protocol (default 30; 0 for none).
    #[arg(long)]
    pub many_seeds: Option<usize>,
    /// Sets `alpha` (UCB confidence weight) in every method whose policy
    /// config has one (the paper's methods: 0.5; the paper does not state it).
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Sets `lambda` (ridge strength) in every method whose policy config has one.
    #[arg(long)]
    pub lambda: Option<f64>,
    #[command(flatten)]
    pub threads: super::Threads,
    /// Also write `docs/results/reproduce.json` and `EXPERIMENTS.md` under
    /// this repository root (`.` from a checkout), from this run's results.
    #[arg(long, value_name = "ROOT")]
    pub write_docs: Option<PathBuf>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: ReproduceArgs) -> hil_core::Result<()> {
    let t0 = Instant::now();
    let mut settings = match &args.settings {
        Some(p) => ProtocolSettings::load(p)?,
        None if args.quick => ProtocolSettings::quick(),
        None => ProtocolSettings::paper(),
    };
    if let Some(d) = &args.dataset {
        settings.dataset = Some(d.clone());
    }
    if let Some(n) = args.many_seeds {
        settings.many_seeds = n;
    }
    if let Some(s) = args.seed {
        settings.seed = s;
    }
    for (key, value) in [("alpha", args.alpha), ("lambda", args.lambda)] {
        if let Some(v) = value {
            for m in &mut settings.methods {
                if m.policy.contains_key(key) {
                    m.policy.insert(key.into(), toml::Value::Float(v));
                }
            }
        }
    }
    let protocol = Protocol::from_settings(settings)?.with_runner(args.threads.runner()?);
    let (settings, dataset) = (&protocol.settings, &protocol.dataset);
    let threads = protocol.runner.threads();
    let total = protocol.jobs()?.len();
    let setup_s = t0.elapsed().as_secs_f64();
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} episodes (eta {eta})",
            )
            .map_err(|e| HilError::invalid_input("progress template", e.to_string()))?,
        );
        b
    };
    let t1 = Instant::now();
    let records = protocol.run_all(&|done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let runs_s = t1.elapsed().as_secs_f64();

    let mut timing = Timing {
        setup_s,
        runs_s,
        report_s: 0.0,
        threads,
    };
    let (reproduction, written) = report(&protocol, &records, Some(&args.out), &mut timing)?;
    let docs = match &args.write_docs {
        Some(root) => hil_experiments::docs::write_docs(root, &reproduction, &timing)?,
        None => Vec::new(),
    };

    if !args.quiet {
        note!(
            "{} episodes on {threads} thread(s): setup {:.2} s, runs {:.2} s, report {:.2} s",
            records.len(),
            setup_s,
            runs_s,
            timing.report_s
        );
        note!("data: {}", dataset.provenance);
        let plot_w = settings.figure_w_task();
        let results = reproduction.headline();
        outln!(
            "w_task = {plot_w}, test set, {} environment seeds, mean ± {} (synthetic data, not the paper's results):",
            results.n_env_seeds,
            match results.spread {
                hil_experiments::results::Spread::Std => "population std",
                hil_experiments::results::Spread::Se => "standard error",
            }
        )?;
        for m in &results.models {
            for method in &settings.methods {
                if let Some(r) = results.row(m, plot_w, &method.label) {
                    outln!(
                        "  {m:<13} {:<16} r_task_avg {:.3} ± {:.3}  ΔWL {:+.3} ± {:.3}  M_wt {:.3} ± {:.3}  f_q {:.3} ± {:.3}{}",
                        method.label,
                        r.test.r_task_avg.mean,
                        results.spread.of(r.test.r_task_avg),
                        r.test.delta_wl.mean,
                        results.spread.of(r.test.delta_wl),
                        r.test.m_wt.mean,
                        results.spread.of(r.test.m_wt),
                        r.test.f_q.mean,
                        results.spread.of(r.test.f_q),
                        r.selected
                            .as_ref()
                            .map_or(String::new(), |h| format!("  ({} = {})", h.name, h.value))
                    )?;
                }
            }
        }
        for f in written
            .iter()
            .flat_map(Written::paths)
            .chain(docs.iter().map(PathBuf::as_path))
        {
            outln!("wrote {}", f.display())?;
        }
    }
    Ok(())
}
