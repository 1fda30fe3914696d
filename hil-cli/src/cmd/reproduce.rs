//! `hil reproduce`: rerun every simulated experiment of the paper.
//!
//! The protocol itself lives in `hil_envs::protocol` (it only knows the
//! `Policy` and `WorkloadModel` traits); this command supplies the paper's
//! policies (hil-policies, one estimator pretrained once and cloned per run)
//! and the bundled simulation workload models (hil-workload).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use hil_core::{HilError, Policy, QueryKind};
use hil_envs::env::{PretrainReward, pretraining_data};
use hil_envs::output::{Timing, write_outputs};
use hil_envs::protocol::{Family, NamedModel, PolicySpec, Protocol, ProtocolSettings};
use hil_envs::results::aggregate;
use hil_envs::{FoodDataset, bundled_dataset};
use hil_policies::{
    AlwaysQuery, AlwaysQueryParams, LinUcb, LinUcbExpDecay, LinUcbExpDecayParams, LinUcbParams,
    LinUcbQg, LinUcbQgParams, LinearArms,
};

/// The simulation workload models of the paper, by bundled name.
pub const SIM_MODELS: [&str; 3] = ["f1_sim", "f2_sim", "f12_sim"];

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
    /// Protocol settings file (TOML, every field of `ProtocolSettings`),
    /// instead of the paper's (or --quick) settings.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// A food dataset directory instead of the bundled synthetic one.
    #[arg(long)]
    pub dataset: Option<PathBuf>,
    /// UCB confidence weight α of the LinUCB family.
    #[arg(long, default_value_t = DEFAULT_ALPHA)]
    pub alpha: f64,
    /// Ridge strength λ of the shared estimator.
    #[arg(long, default_value_t = 1.0)]
    pub lambda: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Default α (the paper does not state its value).
pub const DEFAULT_ALPHA: f64 = 0.5;

pub fn run(args: ReproduceArgs) -> hil_core::Result<()> {
    let t0 = Instant::now();
    let dataset: Arc<FoodDataset> = match &args.dataset {
        Some(p) => Arc::new(FoodDataset::load(p)?),
        None => bundled_dataset()?,
    };
    let mut settings = match &args.settings {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| HilError::io("reading", p, e))?;
            hil_core::config::parse_toml::<ProtocolSettings>(&text, p)?
        }
        None if args.quick => ProtocolSettings::quick(),
        None => ProtocolSettings::paper(),
    };
    if let Some(s) = args.seed {
        settings.seed = s;
    }
    let models = SIM_MODELS
        .iter()
        .map(|n| {
            Ok(NamedModel {
                name: n.to_string(),
                model: hil_workload::bundled::load(n)?,
            })
        })
        .collect::<hil_core::Result<Vec<_>>>()?;
    settings.validate(&dataset, &models)?;

    // Pretrain once; every run clones the estimator.
    let pre = pretraining_data(
        &dataset,
        &settings.split.pretrain,
        PretrainReward::Probability,
        settings.seed,
    )?;
    let mut arms = LinearArms::new(dataset.actions.len(), dataset.context_dim, args.lambda)?;
    arms.pretrain(&pre)?;
    let alpha = args.alpha;
    let kind = QueryKind::default();
    let factory = move |spec: &PolicySpec| -> hil_core::Result<Box<dyn Policy>> {
        Ok(match *spec {
            PolicySpec::Linucb => Box::new(LinUcb::new(LinUcbParams::new(alpha)?, arms.clone())),
            PolicySpec::AlwaysQuery => Box::new(AlwaysQuery::new(
                AlwaysQueryParams::new(alpha, kind)?,
                arms.clone(),
            )),
            PolicySpec::LinucbExpDecay { c } => Box::new(LinUcbExpDecay::new(
                LinUcbExpDecayParams::new(alpha, c, kind)?,
                arms.clone(),
            )),
            PolicySpec::LinucbQg { w } => Box::new(LinUcbQg::new(
                LinUcbQgParams::new(alpha, w, kind)?,
                arms.clone(),
            )),
        })
    };
    let setup_s = t0.elapsed().as_secs_f64();

    let protocol = Protocol {
        settings: settings.clone(),
        dataset: dataset.clone(),
        models: models.clone(),
        factory: &factory,
    };
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let total = protocol.jobs().len();
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
    let records = protocol.run_all(threads, &|done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let runs_s = t1.elapsed().as_secs_f64();

    let t2 = Instant::now();
    let results = aggregate(&settings, &models, &records, &dataset.provenance)?;
    let mut timing = Timing {
        setup_s,
        runs_s,
        report_s: 0.0,
        threads,
    };
    let plot_model = if models.iter().any(|m| m.name == "f2_sim") {
        "f2_sim"
    } else {
        &models[0].name
    };
    let plot_w = if settings.w_tasks.iter().any(|w| (w - 0.7).abs() < 1e-9) {
        0.7
    } else {
        settings.w_tasks[0]
    };
    // Write once to measure, then again with the report time included.
    write_outputs(
        &args.out, &results, &records, &models, plot_model, plot_w, &timing,
    )?;
    timing.report_s = t2.elapsed().as_secs_f64();
    let written = write_outputs(
        &args.out, &results, &records, &models, plot_model, plot_w, &timing,
    )?;

    if !args.quiet {
        eprintln!(
            "{} episodes on {threads} thread(s): setup {:.2} s, runs {:.2} s, report {:.2} s",
            records.len(),
            setup_s,
            runs_s,
            timing.report_s
        );
        eprintln!("data: {}", dataset.provenance);
        println!("w_task = {plot_w} (test set; synthetic data, not the paper's results):");
        for m in &results.models {
            for f in Family::ALL {
                if let Some(r) = results.row(m, plot_w, f) {
                    println!(
                        "  {m:<8} {:<16} r_task_avg {:.3} ± {:.3}  ΔWL {:+.3}  M_wt {:.3} ± {:.3}  f_q {:.3}{}",
                        f.display(),
                        r.test.r_task_avg.mean,
                        r.test.r_task_avg.std,
                        r.test.delta_wl.mean,
                        r.test.m_wt.mean,
                        r.test.m_wt.std,
                        r.test.f_q.mean,
                        r.selected
                            .as_ref()
                            .map_or(String::new(), |h| format!("  ({} = {})", h.name, h.value))
                    );
                }
            }
        }
        println!("wrote {}", written.results.display());
        println!("wrote {}", written.tables.display());
        for f in &written.figures {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}
