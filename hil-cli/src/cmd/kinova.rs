//! `hil kinova calibrate` and `hil demo kinova`: the MuJoCo Kinova Gen3
//! feeding simulation.
//!
//! - `hil kinova calibrate --trials 30 --json` runs every (food, action)
//!   pair in randomised simulated attempts and prints the achieved success
//!   rate beside the published one, with attempts per second and each
//!   cell's p-value against the published counts; `--seeds N` repeats it
//!   under N master seeds and reports the spread and the pooled attempts.
//! - `hil demo kinova` runs the paper's real-robot user-study protocol
//!   (`hil_experiments::user_study`) in simulation: a plate of banana,
//!   carrot and cantaloupe, N_att = 3, the methods LinUCB, AlwaysQuery and
//!   LinUCB-QG, 2 repetitions in counterbalanced order; prints r_task_avg,
//!   n_success and n_q per plate and their mean ± standard error per method.
//!   This file only reads arguments, renders keyframes and prints.

use crate::out::{note, outln};
use std::path::{Path, PathBuf};

use hil_config::limits;
use hil_core::{HilError, Result};
use hil_experiments::user_study::text::{NOTE, over_seeds_text, result_text};
use hil_experiments::user_study::{Plate, UserStudyConfig};
use hil_kinova_mujoco::calibration_text::{
    over_seeds_text as calibration_over_seeds_text, run_text,
};
use hil_kinova_mujoco::{
    AttemptLog, CalibrationOptions, FoodKind, Label, RollBy, calibrate_over_seeds, parse_labels,
};

/// Arguments of `hil kinova`.
#[derive(Debug, clap::Args)]
pub struct KinovaArgs {
    #[command(subcommand)]
    pub command: KinovaCommand,
}

/// Subcommands of `hil kinova`.
#[derive(Debug, clap::Subcommand)]
pub enum KinovaCommand {
    /// Success rate per (food, action) over randomised simulated trials,
    /// beside the published rates.
    Calibrate(CalibrateArgs),
    /// Print the food models a run uses (the built-in, calibrated ones, or
    /// those with a food-models file's changes) as a food-models file: the
    /// knobs of every food kind and their values, to copy and edit.
    FoodModels(FoodModelsArgs),
}

/// Arguments of `hil kinova food-models`.
#[derive(Debug, clap::Args)]
pub struct FoodModelsArgs {
    /// A food-models file whose changes to apply before printing.
    #[arg(long, value_name = "FILE")]
    pub food_models: Option<PathBuf>,
}

/// Arguments of `hil kinova calibrate`.
#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {
    /// Trials per (food, action).
    #[arg(long, default_value_t = 30)]
    pub trials: usize,
    /// Master seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Runs this many master seeds (`--seed`, `--seed`+1, ...) and reports
    /// how one run's figures spread over them (mean ± standard error, runs
    /// meeting the target) and every run's attempts pooled.
    #[arg(long, default_value_t = 1)]
    pub seeds: u64,
    /// Foods to run (default: the three calibrated ones, banana, carrot,
    /// cantaloupe; the derived honeydew, kiwi and celery may be named).
    #[arg(long, value_delimiter = ',')]
    pub foods: Vec<String>,
    /// Placement settings the trials cycle through (default: isolated,wall,lettuce).
    #[arg(long, value_delimiter = ',')]
    pub settings: Vec<String>,
    #[command(flatten)]
    pub threads: super::Threads,
    /// Write every attempt (setting, seed, stop reason, forces, tine
    /// counts, heights) to this file as JSON lines.
    #[arg(long)]
    pub attempts: Option<PathBuf>,
    /// The tool: `arm_yaw` (default: a rigid fork that the arm turns about
    /// the vertical, as in the published data set the rates come from, so
    /// the comparison is like with like) or `fork_gamma` (the study robot's
    /// 2-DoF fork, whose γ joint turns the tine row about the pitched
    /// handle and whose servos yield: the same foods on another tool).
    #[arg(long, default_value = "arm_yaw")]
    pub roll_by: String,
    /// A food-models file (TOML: a table per food, e.g. `[banana]`, whose
    /// keys replace that food's built-in mechanics, such as
    /// `puncture_force = [0.6, 0.3]`): try other mechanics or fit your own
    /// without rebuilding. The report names the file and the foods it
    /// changed. Errors name file, line and field.
    #[arg(long, value_name = "FILE")]
    pub food_models: Option<PathBuf>,
    /// Print a JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also keep the printed report as a Markdown results page at this
    /// path (e.g. docs/results/kinova-calibration.md), naming this command line.
    #[arg(long, value_name = "FILE", conflicts_with = "json")]
    pub write_doc: Option<PathBuf>,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Arguments of `hil demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    #[command(subcommand)]
    pub command: DemoCommand,
}

/// Subcommands of `hil demo`.
#[derive(Debug, clap::Subcommand)]
pub enum DemoCommand {
    /// The real-robot user-study protocol, in the MuJoCo simulation.
    Kinova(KinovaDemoArgs),
}

/// Arguments of `hil demo kinova`.
#[derive(Debug, clap::Args)]
pub struct KinovaDemoArgs {
    /// Repetitions of each method [default: the file's, else 2].
    #[arg(long)]
    pub repetitions: Option<usize>,
    /// Attempts per item, N_att [default: the file's, else 3].
    #[arg(long)]
    pub n_att: Option<u32>,
    /// Master seed [default: the file's, else 7].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Run the whole study (pretraining, validation, plates) on this many
    /// consecutive master seeds and report every figure as the mean ± the
    /// standard error over the seeds.
    #[arg(long, default_value_t = 1)]
    pub seeds: usize,
    #[command(flatten)]
    pub threads: super::Threads,
    /// Write PNG keyframes of every attempt into this directory (offscreen
    /// EGL; needs the `kinova_feeding` environment).
    #[arg(long)]
    pub render: Option<PathBuf>,
    /// A user-study file (see examples/configs/user-study.toml) changing
    /// the protocol.
    ///
    /// Top-level keys: `plugins`, `seed`, `repetitions`, `[session]`,
    /// `[environment]`, `[workload]`, `[channel]` and `[[methods]]` (each a
    /// `label` and a `policy` table). Components are named by `type`, built
    /// in or registered by a plugin the file lists. Every key may be left
    /// out and then takes the paper's protocol, which is that example file:
    /// a component table or the methods list given in the file replaces the
    /// default one as a whole; `[session]` is merged key by key. The flags
    /// --repetitions, --n-att and --seed override the file. Errors name the
    /// file, line and field.
    #[arg(long, verbatim_doc_comment)]
    pub components: Option<PathBuf>,
    /// Print a JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also keep the printed report as a Markdown results page at this
    /// path (e.g. docs/results/kinova-user-study.md), naming this command line.
    #[arg(long, value_name = "FILE", conflicts_with = "json")]
    pub write_doc: Option<PathBuf>,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `hil kinova ...`.
pub fn kinova(args: KinovaArgs) -> Result<()> {
    match args.command {
        KinovaCommand::Calibrate(a) => calibrate(a),
        KinovaCommand::FoodModels(a) => {
            let models = hil_kinova_mujoco::FoodModels::from_file(a.food_models.as_deref())?;
            outln!("{}", models.to_toml()?)
        }
    }
}

/// Runs `hil demo ...`.
pub fn demo(args: DemoArgs) -> Result<()> {
    match args.command {
        DemoCommand::Kinova(a) => demo_kinova(a),
    }
}

/// The values named by a list flag, or all of them when it is not given.
fn labels_or_all<T: Label>(flag: &str, given: &[String]) -> Result<Vec<T>> {
    if given.is_empty() {
        Ok(T::all().to_vec())
    } else {
        parse_labels(flag, given)
    }
}

fn calibrate(args: CalibrateArgs) -> Result<()> {
    limits::check_count("--trials", args.trials, limits::TRIALS)?;
    let seeds = limits::consecutive_seeds("--seeds", args.seed, args.seeds)?;
    let roll_by = RollBy::parse(&args.roll_by).ok_or_else(|| {
        HilError::invalid_parameter(
            "--roll-by",
            args.roll_by.clone(),
            "expected fork_gamma or arm_yaw",
        )
    })?;
    let opts = CalibrationOptions {
        roll_by,
        foods: if args.foods.is_empty() {
            FoodKind::SCENE.to_vec()
        } else {
            parse_labels("--foods", &args.foods)?
        },
        settings: labels_or_all("--settings", &args.settings)?,
        trials: args.trials,
        seed: args.seed,
        threads: args.threads.threads,
        food_models: args.food_models.clone(),
    };
    let quiet = args.quiet;
    let runs = args.seeds;
    let progress = |run: usize, done: usize, total: usize| {
        if !quiet && (done % 10 == 0 || done == total) {
            let of_runs = if runs > 1 {
                format!(" (seed {} of {runs})", run + 1)
            } else {
                String::new()
            };
            crate::out::stderr(format_args!("\rsimulated {done}/{total} attempts{of_runs}"));
            if done == total {
                note!();
            }
        }
    };
    // Created before the run, so a bad path fails at once.
    let log = args
        .attempts
        .as_deref()
        .map(AttemptLog::create)
        .transpose()?;
    let mut records = Vec::new();
    let mut over = calibrate_over_seeds(&opts, &seeds, &progress, &mut |r| {
        if log.is_some() {
            records.push(r.clone());
        }
    })?;
    if let Some(log) = log {
        log.write(&records)?;
    }
    if over.runs.len() == 1 {
        let report = over.runs.remove(0);
        if args.json {
            return print_json(&report);
        }
        return super::emit_report(
            &run_text(&opts, &report),
            args.write_doc.as_deref(),
            CALIBRATION_TITLE,
        );
    }
    if args.json {
        return print_json(&over);
    }
    super::emit_report(
        &calibration_over_seeds_text(&over),
        args.write_doc.as_deref(),
        CALIBRATION_TITLE,
    )
}

fn print_json(value: &impl serde::Serialize) -> Result<()> {
    outln!(
        "{}",
        serde_json::to_string_pretty(value).map_err(|e| HilError::serde("report", e))?
    )?;
    Ok(())
}

/// The study `hil demo kinova` runs: the paper's protocol, changed by
/// `--components` and then by the flags.
/// Where the study file's relative paths resolve: its folder, or `.`.
fn components_dir(args: &KinovaDemoArgs) -> PathBuf {
    args.components
        .as_deref()
        .and_then(Path::parent)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn demo_config(args: &KinovaDemoArgs) -> Result<UserStudyConfig> {
    // The flags are checked here, so that a bad value names the flag.
    if let Some(r) = args.repetitions {
        limits::check_count("--repetitions", r, limits::EPISODES)?;
    }
    if let Some(n) = args.n_att {
        limits::check_count("--n-att", n, limits::ATTEMPTS_PER_ITEM)?;
    }
    let mut cfg = match &args.components {
        Some(path) => UserStudyConfig::load(path)?,
        None => UserStudyConfig::paper(),
    };
    if let Some(r) = args.repetitions {
        cfg.repetitions = r;
    }
    if let Some(n) = args.n_att {
        cfg.session.n_att = n;
    }
    if let Some(s) = args.seed {
        cfg.seed = s;
    }
    cfg.validate()?;
    Ok(cfg)
}

fn demo_kinova(args: KinovaDemoArgs) -> Result<()> {
    limits::check_count("--seeds", args.seeds, limits::SEEDS)?;
    if args.seeds > 1 {
        return demo_many_seeds(&args);
    }
    let cfg = demo_config(&args)?;
    let quiet = args.quiet;
    if !quiet {
        note!("building the environment and its pretraining data (once, for every method)");
    }
    let run = cfg.run_pictured(
        &components_dir(&args),
        args.render.as_deref(),
        &mut |plate: &Plate| {
            if !quiet {
                note!(
                    "repetition {} plate {}: {}",
                    plate.repetition,
                    plate.position,
                    plate.label
                );
            }
        },
        &mut |note| note!("note: {note}"),
    )?;
    if args.json {
        print_json_with_note(&run.result)?;
    } else {
        super::emit_report(
            &result_text(&run.result),
            args.write_doc.as_deref(),
            USER_STUDY_TITLE,
        )?;
    }
    if let Some(k) = run.keyframes {
        note!("wrote {} keyframes to {}", k.written, k.dir.display());
    }
    Ok(())
}

/// Headings of the results pages `--write-doc` keeps.
const CALIBRATION_TITLE: &str = "Kinova simulator calibration against the published success rates";
const USER_STUDY_TITLE: &str = "The user-study protocol in the Kinova simulation";

/// `value`'s JSON object with the [`NOTE`] beside its fields, printed.
fn print_json_with_note(value: &impl serde::Serialize) -> Result<()> {
    let mut out = serde_json::to_value(value).map_err(|e| HilError::serde("demo report", e))?;
    if let Some(fields) = out.as_object_mut() {
        fields.insert("note".into(), NOTE.into());
    }
    outln!(
        "{}",
        serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("demo report", e))?
    )?;
    Ok(())
}

/// `hil demo kinova --seeds N`: the whole study on N consecutive master
/// seeds (in parallel), every figure as mean ± standard error over seeds.
fn demo_many_seeds(args: &KinovaDemoArgs) -> Result<()> {
    if args.render.is_some() {
        return Err(HilError::invalid_parameter(
            "--render",
            "given",
            "pictures are written for a single seed; drop --seeds or --render",
        ));
    }
    let cfg = demo_config(args)?;
    let seeds = limits::consecutive_seeds("--seeds", cfg.seed, args.seeds)?;
    let quiet = args.quiet;
    let over = cfg.run_over_seeds(
        &components_dir(args),
        &seeds,
        &args.threads.runner()?,
        &|seed| {
            if !quiet {
                note!("seed {seed} done");
            }
        },
    )?;
    if args.json {
        return print_json_with_note(&over);
    }
    super::emit_report(
        &over_seeds_text(&over),
        args.write_doc.as_deref(),
        USER_STUDY_TITLE,
    )
}
