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

use std::path::{Path, PathBuf};

use hil_core::{HilError, Result};
use hil_experiments::user_study::{Plate, UserStudyConfig, UserStudyOverSeeds, UserStudyResult};
use hil_kinova_mujoco::{
    AttemptLog, CalibrationOptions, CalibrationReport, CalibrationRow, Consistency, FoodKind,
    Label, RollBy, calibrate_over_seeds, parse_labels,
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
    /// Print a JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
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
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `hil kinova ...`.
pub fn kinova(args: KinovaArgs) -> Result<()> {
    match args.command {
        KinovaCommand::Calibrate(a) => calibrate(a),
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
    if args.trials == 0 {
        return Err(HilError::invalid_parameter(
            "--trials",
            "0",
            "must be at least 1",
        ));
    }
    if args.seeds == 0 {
        return Err(HilError::invalid_parameter(
            "--seeds",
            "0",
            "must be at least 1",
        ));
    }
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
            eprint!("\rsimulated {done}/{total} attempts{of_runs}");
            if done == total {
                eprintln!();
            }
        }
    };
    // Created before the run, so a bad path fails at once.
    let log = args
        .attempts
        .as_deref()
        .map(AttemptLog::create)
        .transpose()?;
    let seeds: Vec<u64> = (0..args.seeds).map(|i| args.seed.wrapping_add(i)).collect();
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
            print_json(&report)?;
        } else {
            print_run(&opts, &report);
        }
        return Ok(());
    }
    if args.json {
        return print_json(&over);
    }
    let first = &over.runs[0];
    println!(
        "{} runs, master seeds {}..={}; attempts of all runs pooled, rate ± binomial SE (published):",
        over.runs.len(),
        seeds[0],
        seeds[seeds.len() - 1]
    );
    print_tool(first.roll_by);
    print_table(&over.pooled);
    for (run, seed) in over.runs.iter().zip(&seeds) {
        println!(
            "seed {seed}: mean |simulated - published| {:.3}, largest {:.3}: target {}",
            run.mean_abs_error,
            run.max_abs_error,
            met(run.meets_target)
        );
    }
    let t = over.target;
    println!(
        "over {} runs (mean ± SE): mean |simulated - published| {:.3} ± {:.3}, largest {:.3} ± {:.3} (a perfect simulator: {:.3} and {:.3}); target (mean <= {:.2}, no cell off by more than {:.2}) met in {} of {} runs, where a perfect simulator meets it in {:.0}% of runs",
        over.runs.len(),
        over.mean_abs_error.mean,
        over.mean_abs_error.se,
        over.max_abs_error.mean,
        over.max_abs_error.se,
        over.noise_floor,
        over.noise_floor_worst_cell,
        t.mean_abs_error,
        t.worst_cell,
        over.runs_meeting_target,
        over.runs.len(),
        100.0 * over.perfect_simulator_meets_target
    );
    print_consistency("pooled overall cells", &over.pooled_consistency);
    print_consistency(
        "pooled per-setting cells",
        &over.pooled_consistency_by_setting,
    );
    print!("seed {}'s run: ", seeds[0]);
    print_throughput(first);
    Ok(())
}

fn print_json(value: &impl serde::Serialize) -> Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(value).map_err(|e| HilError::serde("report", e))?
    );
    Ok(())
}

fn met(yes: bool) -> &'static str {
    if yes { "met" } else { "not met" }
}

/// One run: the table and how it stands against the target.
fn print_run(opts: &CalibrationOptions, report: &CalibrationReport) {
    let per_setting = opts.trials / opts.settings.len();
    println!(
        "Simulated success rate (published rate) per action; {} trials each ({} per setting).",
        opts.trials, per_setting
    );
    print_tool(report.roll_by);
    print_table(&report.rows);
    println!(
        "mean |simulated - published| = {:.3} overall (largest {:.3}), {:.3} per setting; hold {:.1} s",
        report.mean_abs_error,
        report.max_abs_error,
        report.mean_abs_error_by_setting,
        report.hold_s,
    );
    println!(
        "a perfect simulator (true rates = the published ones) would still average {:.3}, with a worst cell of {:.3} expected: the sampling noise of {} published trials per setting and of these",
        report.noise_floor,
        report.noise_floor_worst_cell,
        hil_paper::food_data::TRIALS_PER_SETTING
    );
    let t = report.target;
    println!(
        "target (mean <= {:.2}, no cell off by more than {:.2}): {}; a perfect simulator meets it in {:.0}% of runs with these trial counts",
        t.mean_abs_error,
        t.worst_cell,
        met(report.meets_target),
        100.0 * report.perfect_simulator_meets_target
    );
    print_consistency("overall cells", &report.consistency);
    print_consistency("per-setting cells", &report.consistency_by_setting);
    print_throughput(report);
}

fn print_tool(roll_by: RollBy) {
    println!(
        "Simulated attempts with synthetic food properties, tool `{}`{}; published: Feng et al. 2019.",
        roll_by.name(),
        match roll_by {
            RollBy::ArmYaw => " (the published data set's rigid fork)",
            RollBy::ForkGamma =>
                " (the study's 2-DoF fork: not the tool the published rates measured)",
        }
    );
}

/// The rows, one line per food and one per setting under it.
fn print_table(rows: &[CalibrationRow]) {
    print!("{:<22}", "food");
    for a in hil_envs::feeding::action_space().names() {
        print!("{a:>18}");
    }
    println!();
    for chunk in rows.chunks(6) {
        print!("{:<22}", chunk[0].food);
        for r in chunk {
            print!(
                "{:>18}",
                cell(r.counts.rate, r.counts.se, r.published, r.p_value)
            );
        }
        println!();
        for (i, c) in chunk[0].by_setting.iter().enumerate() {
            print!("{:<22}", format!("  {}", c.setting.name()));
            for r in chunk {
                let c = &r.by_setting[i];
                print!(
                    "{:>18}",
                    cell(c.counts.rate, c.counts.se, c.published, c.p_value)
                );
            }
            println!();
        }
    }
    println!("* p < 0.05: a difference from the published rate that chance alone explains poorly");
    let discarded: usize = rows.iter().map(|r| r.counts.discarded).sum();
    println!(
        "{discarded} of {} attempts discarded (fewer than {} tines touched the item, as in the published data set); rates are over the rest",
        rows.iter().map(|r| r.counts.trials).sum::<usize>(),
        hil_kinova_mujoco::MIN_TINES_TOUCHED
    );
}

fn print_consistency(what: &str, c: &Consistency) {
    println!(
        "chance alone (Fisher's exact test per cell, simulated vs published counts), {what}: {} of {} below p = 0.05 (p = {:.3} for this many); least consistent {} (p = {:.3}; {:.3} after Bonferroni over {} cells)",
        c.below_0_05,
        c.cells,
        c.p_this_many_below_0_05,
        if c.least_consistent.is_empty() {
            "-"
        } else {
            &c.least_consistent
        },
        c.smallest_p,
        c.smallest_p_adjusted,
        c.cells
    );
}

fn print_throughput(report: &CalibrationReport) {
    println!(
        "{:.1} attempts/s on {} threads ({:.1} per core); {:.0} steps per attempt at {:.1} µs per mj_step; {:.1}% of time outside mj_step",
        report.attempts_per_second,
        report.threads,
        report.attempts_per_second_per_core,
        report.steps_per_attempt,
        report.micros_per_step,
        100.0 * report.overhead_share
    );
}

/// `rate±se (published)`, marked `*` when chance alone explains the
/// difference poorly (Fisher's exact p < 0.05).
fn cell(rate: f64, se: f64, published: Option<f64>, p_value: Option<f64>) -> String {
    let p = published.map_or("  -  ".into(), |p| format!("{p:.2}"));
    let mark = if p_value.is_some_and(|p| p < 0.05) {
        "*"
    } else {
        " "
    };
    format!("{rate:.2}±{se:.2} ({p}){mark}")
}

/// What the results are, printed with them.
const NOTE: &str = "simulation of the user-study protocol; food properties are synthetic, \
                    calibrated to published success rates, and the workload model is a \
                    bundled synthetic one: these are not the paper's results";

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
    for (flag, zero) in [
        ("--repetitions", args.repetitions == Some(0)),
        ("--n-att", args.n_att == Some(0)),
    ] {
        if zero {
            return Err(HilError::invalid_parameter(flag, 0, "must be at least 1"));
        }
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
    if args.seeds == 0 {
        return Err(HilError::invalid_parameter(
            "--seeds",
            0,
            "must be at least 1",
        ));
    }
    if args.seeds > 1 {
        return demo_many_seeds(&args);
    }
    let cfg = demo_config(&args)?;
    let quiet = args.quiet;
    if !quiet {
        eprintln!("building the environment and its pretraining data (once, for every method)");
    }
    let run = cfg.run_pictured(
        &components_dir(&args),
        args.render.as_deref(),
        &mut |plate: &Plate| {
            if !quiet {
                eprintln!(
                    "repetition {} plate {}: {}",
                    plate.repetition, plate.position, plate.label
                );
            }
        },
        &mut |note| eprintln!("note: {note}"),
    )?;
    print_result(&run.result, args.json)?;
    if let Some(k) = run.keyframes {
        eprintln!("wrote {} keyframes to {}", k.written, k.dir.display());
    }
    Ok(())
}

/// `value`'s JSON object with the [`NOTE`] beside its fields, printed.
fn print_json_with_note(value: &impl serde::Serialize) -> Result<()> {
    let mut out = serde_json::to_value(value).map_err(|e| HilError::serde("demo report", e))?;
    if let Some(fields) = out.as_object_mut() {
        fields.insert("note".into(), NOTE.into());
    }
    println!(
        "{}",
        serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("demo report", e))?
    );
    Ok(())
}

/// `12.3 ± 0.4`, or the mean alone where one plate leaves the error undefined.
fn pm(mean: f64, sem: Option<f64>, digits: usize) -> String {
    match sem {
        Some(s) => format!("{mean:.digits$} ± {s:.digits$}"),
        None => format!("{mean:.digits$}"),
    }
}

fn print_result(result: &UserStudyResult, json: bool) -> Result<()> {
    if json {
        return print_json_with_note(result);
    }
    let p = &result.protocol;
    println!(
        "User-study protocol in simulation ({}: {}; N_att = {}; {} repetitions; seed {}).",
        p.environment,
        p.foods.join(", "),
        p.n_att,
        p.repetitions,
        p.seed
    );
    println!("Note: {NOTE}.");
    println!(
        "{:<12} {:>4} {:>4} {:>11} {:>10} {:>4}",
        "method", "rep", "pos", "r_task_avg", "n_success", "n_q"
    );
    for p in &result.plates {
        println!(
            "{:<12} {:>4} {:>4} {:>11.3} {:>10} {:>4}",
            p.method, p.repetition, p.position, p.r_task_avg, p.n_success, p.n_q
        );
    }
    for sel in &result.selections {
        let tried: Vec<String> = sel
            .grid
            .iter()
            .zip(&sel.m_wt)
            .zip(&sel.n_q)
            .map(|((v, m), q)| format!("{v}: {:.3} (n_q {q:.2})", m.mean))
            .collect();
        println!(
            "{} {} = {} chosen by mean M_wt({}) over {} validation plates per value: {}",
            sel.method,
            sel.parameter,
            sel.chosen,
            sel.w_task,
            sel.plates,
            tried.join(", ")
        );
    }
    println!("\nper method (mean ± standard error over its plates):");
    for s in &result.methods {
        println!(
            "{:<12} r_task_avg {}  n_success {}  n_q {}  ({} plates)",
            s.method,
            pm(s.r_task_avg, s.r_task_avg_sem, 3),
            pm(s.n_success_per_plate, s.n_success_per_plate_sem, 2),
            pm(s.n_q_per_plate, s.n_q_per_plate_sem, 2),
            s.plates
        );
        let foods: Vec<String> = s
            .n_q_by_food
            .iter()
            .map(|(f, q)| format!("{f} {q:.2}"))
            .collect();
        let attempts: Vec<String> = s
            .n_q_by_attempt
            .iter()
            .enumerate()
            .map(|(i, q)| format!("#{} {q:.2}", i + 1))
            .collect();
        println!(
            "{:<12} asks per plate at {}; at attempt {}",
            "",
            foods.join(", "),
            attempts.join(", ")
        );
    }
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
    let first = cfg.seed;
    let seeds: Vec<u64> = (0..args.seeds as u64)
        .map(|i| first.wrapping_add(i))
        .collect();
    let quiet = args.quiet;
    let over = cfg.run_over_seeds(
        &components_dir(args),
        &seeds,
        &args.threads.runner()?,
        &|seed| {
            if !quiet {
                eprintln!("seed {seed} done");
            }
        },
    )?;
    if args.json {
        return print_json_with_note(&over);
    }
    print_over_seeds(&over);
    Ok(())
}

/// The study over seeds as text.
fn print_over_seeds(over: &UserStudyOverSeeds) {
    let (seeds, rows) = (&over.seeds, &over.methods);
    let first = seeds[0];
    let p = &over.protocol;
    println!(
        "User-study protocol in simulation over {} seeds ({}..={}): {}: {}; N_att = {}; {} repetitions per seed.",
        seeds.len(),
        first,
        first + seeds.len() as u64 - 1,
        p.environment,
        p.foods.join(", "),
        p.n_att,
        p.repetitions
    );
    println!("Note: {NOTE}.");
    println!(
        "per method: mean ± standard error over seeds (each seed's mean over its plates); paper's real study in brackets"
    );
    for row in rows {
        let paper = row.paper.map_or(String::new(), |p| {
            format!(" [{:.2} / {:.2} / {:.2}]", p[0], p[1], p[2])
        });
        let (r, s, q) = (row.r_task_avg, row.n_success_per_plate, row.n_q_per_plate);
        println!(
            "{:<12} r_task_avg {}  n_success {}  n_q {}{paper}",
            row.method,
            pm(r.mean, r.sem(), 3),
            pm(s.mean, s.sem(), 2),
            pm(q.mean, q.sem(), 2)
        );
    }
    println!("where each method asks: queries per plate at each food, and at each attempt index");
    for row in rows {
        let foods: Vec<String> = row
            .n_q_per_plate_by_food
            .iter()
            .map(|(f, m)| format!("{f} {}", pm(m.mean, m.sem(), 2)))
            .collect();
        let attempts: Vec<String> = row
            .n_q_per_plate_by_attempt
            .iter()
            .enumerate()
            .map(|(i, m)| format!("#{} {}", i + 1, pm(m.mean, m.sem(), 2)))
            .collect();
        println!(
            "{:<12} {}; attempt {}",
            row.method,
            foods.join(", "),
            attempts.join(", ")
        );
    }
    for c in over.chosen() {
        println!(
            "{} {} chosen on validation (highest mean M_wt) per seed: {} (mean {})",
            c.method,
            c.parameter,
            c.values
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            pm(c.mean.mean, c.mean.sem(), 2)
        );
    }
}
