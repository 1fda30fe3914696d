//! `hil workload …`: generate study data, select and fit workload models,
//! roll a model out over a query schedule, regenerate the bundled models.

use crate::out::{note, out, outln};
use std::path::PathBuf;
use std::time::Instant;

use hil_core::{HilError, Result, Timestep};
use hil_workload::bundle::{SYNTHETIC_DATA_NOTE, StudySummary, WrittenBundle, write_bundle};
use hil_workload::datasets::DatasetId;
use hil_workload::models::FittedModel;
use hil_workload::rollout::{default_end, parse_schedule, rollout};
use hil_workload::select::{Candidate, SelectOptions, fit_study_model, select_study_models};
use hil_workload::study::Study;
use hil_workload::synth::SynthConfig;

/// Arguments of `hil workload`.
#[derive(Debug, clap::Args)]
pub struct WorkloadArgs {
    #[command(subcommand)]
    command: WorkloadCommand,
}

#[derive(Debug, clap::Subcommand)]
enum WorkloadCommand {
    /// Generate a synthetic study CSV (the paper's design, calibrated to its figures).
    Generate {
        /// Output CSV.
        #[arg(long)]
        out: PathBuf,
        /// Random seed.
        #[arg(long, default_value_t = hil_workload::bundle::STUDY_SEED)]
        seed: u64,
        /// Generator settings as JSON (a `SynthConfig`; default: the calibrated one).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Print nothing.
        #[arg(long, short)]
        quiet: bool,
    },
    /// The synthetic generator over many seeds: D1/D2 means and sds over
    /// seeds beside the paper's (one generated study is one draw).
    Seeds {
        /// Number of generator seeds (0..count).
        #[arg(long, default_value_t = 100)]
        count: u64,
        /// Generator settings as JSON (default: the calibrated one).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Recalibrate the level and spread parameters (mean,
        /// population_shift, survey_sd, limited_survey_sd) until the D1/D2
        /// means and sds over seeds are within 0.002 of the paper's, and
        /// print the calibrated parameters.
        #[arg(long)]
        centre: bool,
        /// Also keep the printed report as a Markdown results page at this
        /// path (e.g. docs/results/workload-generator-seeds.md), naming this
        /// command line.
        #[arg(long, value_name = "FILE")]
        write_doc: Option<PathBuf>,
    },
    /// Print a study's headline figures (pairs, WL mean ± sd, Mann-Whitney D1 < D2).
    Summary {
        /// Study CSV.
        #[arg(long)]
        data: PathBuf,
    },
    /// Cross-validate every model on D1, D2, D12 and write the selection table.
    Select {
        /// Study CSV.
        #[arg(long)]
        data: PathBuf,
        /// Output directory (selection.md, selection.csv, selection.json).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        cv: CvArgs,
        /// Print only the timing line.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Fit one model on one dataset and write it as JSON.
    Fit {
        /// Study CSV.
        #[arg(long)]
        data: PathBuf,
        /// Dataset: d1, d2 or d12.
        #[arg(long)]
        population: String,
        /// constant, average, exp_impulse, granger, granger_n, granger_r, granger_rn, granger_sim.
        #[arg(long)]
        model: String,
        /// History length H (Granger models).
        #[arg(long)]
        history: Option<usize>,
        /// Output JSON.
        #[arg(long)]
        out: PathBuf,
        /// Name stored in the file (default: derived from the model).
        #[arg(long)]
        name: Option<String>,
        #[command(flatten)]
        cv: CvArgs,
    },
    /// Print (and optionally plot) WL_t of a model over a query schedule.
    Rollout {
        /// Model JSON, or `bundled:NAME` (`hil_workload::bundled::NAMES`: f1_sim, f2_sim, f12_sim, their `_steep` variants, f1_real, f12_real).
        #[arg(long)]
        model: String,
        /// Queries as `t:response/difficulty/distraction,...`, e.g.
        /// `3:mcq/easy/none,9:open_ended/hard/easy` (t in 10 s timesteps;
        /// omitted parts default to mcq/easy/none).
        #[arg(long, default_value = "")]
        schedule: String,
        /// Initial workload WL_0.
        #[arg(long, default_value_t = hil_core::workload::DEFAULT_WL0)]
        wl0: f64,
        /// Last timestep (default: last query + 10).
        #[arg(long)]
        steps: Option<Timestep>,
        /// Write an SVG plot here.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Derive the simulation models (f1_sim, f2_sim, f12_sim and their
    /// `_steep` variants) from the paper's published rows, print how each
    /// meets its targets, and write them (run from the workspace root).
    Calibrate {
        /// The hil-workload crate directory.
        #[arg(long, default_value = "hil-workload")]
        dir: PathBuf,
        /// Only compare with the files there; fail if any differs.
        #[arg(long)]
        check: bool,
    },
    /// Regenerate the bundled study and the study-fitted models
    /// (f1_real, f12_real; run from the workspace root).
    Bundle {
        /// The hil-workload crate directory.
        #[arg(long, default_value = "hil-workload")]
        dir: PathBuf,
        #[command(flatten)]
        cv: CvArgs,
    },
}

#[derive(Debug, clap::Args)]
struct CvArgs {
    /// Seed of the fold assignment.
    #[arg(long = "cv-seed", default_value_t = 0)]
    cv_seed: u64,
    #[command(flatten)]
    threads: super::Threads,
}

impl CvArgs {
    fn options(&self) -> SelectOptions {
        SelectOptions {
            seed: self.cv_seed,
            threads: self.threads.threads,
            ..SelectOptions::default()
        }
    }
}

const SYNTHETIC: &str = SYNTHETIC_DATA_NOTE;

/// Heading of the results page `hil workload seeds --write-doc` writes.
const SEEDS_TITLE: &str = "Workload generator over seeds";

/// Runs `hil workload`.
pub fn run(args: WorkloadArgs) -> Result<()> {
    match args.command {
        WorkloadCommand::Generate {
            out,
            seed,
            config,
            quiet,
        } => {
            let cfg = synth_config(config.as_deref())?;
            let study = cfg.generate(seed)?;
            study.write_csv(&out)?;
            if !quiet {
                outln!(
                    "wrote {} ({} surveys)",
                    out.display(),
                    study.records().len()
                )?;
                out!("{}", StudySummary::of(&study)?.to_text())?;
                outln!("{SYNTHETIC}")?;
            }
            Ok(())
        }
        WorkloadCommand::Summary { data } => {
            let study = Study::load(&data)?;
            // Summarised before anything is printed: a study that cannot be
            // summarised prints only its error.
            let summary = StudySummary::of(&study)?;
            outln!("{}: {} surveys", data.display(), study.records().len())?;
            out!("{}", summary.to_text())?;
            Ok(())
        }
        WorkloadCommand::Select {
            data,
            out,
            cv,
            quiet,
        } => {
            let study = Study::load(&data)?;
            let t0 = Instant::now();
            let opts = cv.options();
            let table = select_study_models(&study, &opts)?;
            let elapsed = t0.elapsed();
            table.write_to(&out)?;
            if !quiet {
                out!("{}", table.to_markdown())?;
                for id in DatasetId::ALL {
                    if let Some(b) = table.best(id) {
                        outln!(
                            "selected on {}: {}{} (median test MSE {:.4})",
                            id.as_str().to_uppercase(),
                            b.candidate.label(),
                            b.candidate
                                .history()
                                .map_or(String::new(), |h| format!(" H = {h}")),
                            b.median
                        )?;
                    }
                }
                outln!("wrote {}/selection.{{md,csv,json}}", out.display())?;
            }
            outln!(
                "selection table: {} rows in {:.3} s (datasets + nested CV, {} threads requested)",
                table.rows.len(),
                elapsed.as_secs_f64(),
                opts.threads
            )?;
            Ok(())
        }
        WorkloadCommand::Fit {
            data,
            population,
            model,
            history,
            out,
            name,
            cv,
        } => {
            // The flags first: a bad one is named before the data is read.
            let id = DatasetId::parse(&population)?;
            let cand = Candidate::parse(&model, history)?;
            let study = Study::load(&data)?;
            let m = fit_study_model(&study, id, cand, &cv.options(), name)?;
            m.save(&out)?;
            outln!(
                "wrote {} ({} on {}, {} pairs)",
                out.display(),
                cand.label(),
                id.as_str().to_uppercase(),
                m.provenance.n_pairs.unwrap_or_default()
            )?;
            Ok(())
        }
        WorkloadCommand::Rollout {
            model,
            schedule,
            wl0,
            steps,
            svg,
        } => {
            let m: FittedModel = match model.strip_prefix("bundled:") {
                Some(name) => hil_workload::bundled::load_fitted(name)?,
                None => FittedModel::load(&model)?,
            };
            let queries = parse_schedule(&schedule)?;
            let end = steps.unwrap_or_else(|| default_end(&queries));
            let points = rollout(&m, wl0, &queries, end)?;
            outln!("t,seconds,wl,query")?;
            for p in &points {
                let asked: Vec<String> = p.asked.iter().map(ToString::to_string).collect();
                outln!("{},{},{:.4},{}", p.t, p.t * 10, p.wl, asked.join(" "))?;
            }
            if let Some(path) = svg {
                let wl: Vec<f64> = points.iter().map(|p| p.wl).collect();
                let asked: Vec<Timestep> = points
                    .iter()
                    .filter(|p| !p.asked.is_empty())
                    .map(|p| p.t)
                    .collect();
                let title = format!("WL_t of {} (WL_0 = {wl0}); Δt = 10 s", m.name);
                let note = match (&m.provenance.data, &m.provenance.note) {
                    (_, Some(note)) => note.clone(),
                    (Some(data), None) => format!("fitted on {data}"),
                    (None, None) => "provenance unknown".to_string(),
                };
                let svg = hil_experiments::plot::workload_curve_svg(&title, &note, &wl, &asked);
                hil_core::files::write_text(&path, &svg)?;
                note!("wrote {}", path.display());
            }
            Ok(())
        }
        WorkloadCommand::Seeds {
            count,
            config,
            centre,
            write_doc,
        } => {
            hil_config::limits::check_count("--count", count, hil_config::limits::SEEDS)?;
            let cfg = synth_config(config.as_deref())?;
            let t0 = Instant::now();
            let mut report = if centre {
                let (c, spread) = hil_workload::seeds::centre(&cfg, 0..count, 0.002, 8)?;
                let p = &c.params;
                format!(
                    "{}calibrated: mean = {}, population_shift = {}, participant_sd = {}, limited_survey_sd = {}\n",
                    spread.to_text(),
                    p.mean,
                    p.population_shift,
                    p.participant_sd,
                    p.limited_survey_sd
                )
            } else {
                hil_workload::seeds::SeedSpread::over(&cfg, 0..count)?.to_text()
            };
            // The note belongs to the report, so a results page carries it too.
            report.push_str(SYNTHETIC);
            report.push('\n');
            super::emit_report(&report, write_doc.as_deref(), SEEDS_TITLE)?;
            note!("{:.1} s.", t0.elapsed().as_secs_f64());
            Ok(())
        }
        WorkloadCommand::Calibrate { dir, check } => {
            let models = hil_experiments::calibrate::all()?;
            out!("{}", hil_experiments::calibrate::report(&models)?)?;
            if !check {
                for m in &models {
                    let path = hil_experiments::calibrate::model_path(&dir, m);
                    m.save(&path)?;
                    note!("wrote {}", path.display());
                }
                return Ok(());
            }
            let stale: Vec<String> = hil_experiments::calibrate::stale_files(&dir, &models)?
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            if !stale.is_empty() {
                return Err(HilError::invalid_input(
                    "calibrated models",
                    format!(
                        "{} differ from the calibration; rerun `hil workload calibrate`",
                        stale.join(", ")
                    ),
                ));
            }
            Ok(())
        }
        WorkloadCommand::Bundle { dir, cv } => {
            let t0 = Instant::now();
            let WrittenBundle { summary, models } = write_bundle(&dir, &cv.options())?;
            for m in &models {
                outln!(
                    "wrote models/{}.json: {}",
                    m.name,
                    m.provenance.note.as_deref().unwrap_or("")
                )?;
            }
            out!("{}", summary.to_text())?;
            outln!(
                "bundle regenerated in {:.2} s. {SYNTHETIC}",
                t0.elapsed().as_secs_f64()
            )?;
            Ok(())
        }
    }
}

/// The generator settings in `path` (JSON), or the calibrated default.
fn synth_config(path: Option<&std::path::Path>) -> Result<SynthConfig> {
    let Some(path) = path else {
        return Ok(SynthConfig::default());
    };
    let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
    serde_json::from_str::<SynthConfig>(&text).map_err(|e| HilError::Data {
        path: path.to_path_buf(),
        record: e.line(),
        field: "(json)".into(),
        why: e.to_string(),
    })
}
