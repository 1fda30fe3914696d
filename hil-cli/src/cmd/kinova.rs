//! `hil kinova calibrate` and `hil demo kinova`: the MuJoCo Kinova Gen3
//! feeding simulation.
//!
//! - `hil kinova calibrate --trials 30 --json` runs every (food, action)
//!   pair in randomised simulated attempts and prints the achieved success
//!   rate beside the published one, with attempts per second.
//! - `hil demo kinova` runs the paper's real-robot user-study protocol in
//!   simulation: a plate of banana, carrot and cantaloupe, N_att = 3, the
//!   methods LinUCB, AlwaysQuery and LinUCB-QG, 2 repetitions in
//!   counterbalanced order; prints r_task_avg, n_success and n_q per plate.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hil_core::config::{BuildContext, PolicyConfig, QueryChannelConfig, WorkloadModelConfig};
use hil_core::{Environment, HilError, Result, Session, SessionSettings};
use std::io::Write;

use hil_kinova_mujoco::calibrate::{CalibrationOptions, calibrate_with};
use hil_kinova_mujoco::food::{Label, parse_labels};
use hil_kinova_mujoco::render::{KeyframeRecorder, KeyframeWriter, RenderingEnv};
use hil_kinova_mujoco::{KinovaFeedingConfig, KinovaFeedingEnv};
use serde::Serialize;

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
    /// Foods to run (default: all).
    #[arg(long, value_delimiter = ',')]
    pub foods: Vec<String>,
    /// Placement settings the trials cycle through (default: isolated,wall,lettuce).
    #[arg(long, value_delimiter = ',')]
    pub settings: Vec<String>,
    /// Worker threads, each with its own simulator (default: one per core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write every attempt (setting, seed, stop reason, forces, tine
    /// counts, heights) to this file as JSON lines.
    #[arg(long)]
    pub attempts: Option<PathBuf>,
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
    /// Repetitions of each method.
    #[arg(long, default_value_t = 2)]
    pub repetitions: usize,
    /// Attempts per item (N_att).
    #[arg(long, default_value_t = 3)]
    pub n_att: u32,
    /// Master seed.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Write PNG keyframes of every attempt into this directory (offscreen EGL).
    #[arg(long)]
    pub render: Option<PathBuf>,
    /// TOML overriding the components: tables `linucb`, `always_query`,
    /// `linucb_qg` (policy configs), `workload`, `channel` and `environment`
    /// (a `kinova_feeding` config without `type`).
    #[arg(long)]
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
    if args.threads == Some(0) {
        return Err(HilError::invalid_parameter(
            "--threads",
            "0",
            "must be at least 1",
        ));
    }
    let opts = CalibrationOptions {
        foods: labels_or_all("--foods", &args.foods)?,
        settings: labels_or_all("--settings", &args.settings)?,
        trials: args.trials,
        seed: args.seed,
        threads: args
            .threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
    };
    let quiet = args.quiet;
    let progress = |done: usize, total: usize| {
        if !quiet && (done % 10 == 0 || done == total) {
            eprint!("\rsimulated {done}/{total} attempts");
            if done == total {
                eprintln!();
            }
        }
    };
    // Create the attempt log before the run, so a bad path fails at once.
    let log_file = match &args.attempts {
        Some(path) => Some((
            path,
            std::fs::File::create(path).map_err(|e| HilError::io("create", path, e))?,
        )),
        None => None,
    };
    let mut records = Vec::new();
    let report = calibrate_with(&opts, &progress, &mut |r| {
        if log_file.is_some() {
            records.push(r.clone());
        }
    })?;
    if let Some((path, file)) = log_file {
        let mut w = std::io::BufWriter::new(file);
        for r in &records {
            let line = serde_json::to_string(r).map_err(|e| HilError::serde("attempt", e))?;
            writeln!(w, "{line}").map_err(|e| HilError::io("write", path, e))?;
        }
        w.flush().map_err(|e| HilError::io("write", path, e))?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| HilError::serde("report", e))?
        );
        return Ok(());
    }
    let per_setting = opts.trials / opts.settings.len();
    println!(
        "Simulated success rate (published rate) per action; {} trials each ({} per setting).",
        opts.trials, per_setting
    );
    println!("Simulated attempts with synthetic food properties; published: Feng et al. 2019.");
    let header = || {
        print!("{:<22}", "food");
        for a in hil_envs::feeding::action_space().names() {
            print!("{a:>13}");
        }
        println!();
    };
    header();
    for chunk in report.rows.chunks(6) {
        print!("{:<22}", chunk[0].food);
        for r in chunk {
            print!("{:>13}", cell(r.rate, r.published));
        }
        println!();
        for (i, c) in chunk[0].by_setting.iter().enumerate() {
            print!("{:<22}", format!("  {}", c.setting.name()));
            for r in chunk {
                let c = &r.by_setting[i];
                print!("{:>13}", cell(c.rate, c.published));
            }
            println!();
        }
    }
    println!(
        "mean |simulated - published| = {:.3} overall, {:.3} per setting; {:.1} attempts/s on {} threads ({:.1} per core); {:.1}% of time outside mj_step",
        report.mean_abs_error,
        report.mean_abs_error_by_setting,
        report.attempts_per_second,
        report.threads,
        report.attempts_per_second_per_core,
        100.0 * report.overhead_share
    );
    Ok(())
}

fn cell(rate: f64, published: Option<f64>) -> String {
    let p = published.map_or("  -  ".into(), |p| format!("{p:.2}"));
    format!("{rate:.2} ({p})")
}

/// The methods of the user study, in the paper's order.
const METHODS: [(&str, &str); 3] = [
    ("LinUCB", "linucb"),
    ("AlwaysQuery", "always_query"),
    ("LinUCB-QG", "linucb_qg"),
];

/// Counterbalanced method order for repetition `rep`: the second
/// repetition reverses the first (ABC, CBA: every method's mean position
/// is the same), and six repetitions use all six orders.
fn method_order(rep: usize) -> [usize; 3] {
    const ORDERS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [2, 1, 0],
        [1, 2, 0],
        [0, 2, 1],
        [2, 0, 1],
        [1, 0, 2],
    ];
    ORDERS[rep % 6]
}

#[derive(Debug, Serialize)]
struct PlateResult {
    method: &'static str,
    repetition: usize,
    position: usize,
    r_task_avg: f64,
    n_success: usize,
    n_q: usize,
    n_steps: usize,
}

#[derive(Debug, Serialize)]
struct MethodSummary {
    method: &'static str,
    r_task_avg: f64,
    n_success_per_plate: f64,
    n_q_per_plate: f64,
}

fn components(path: Option<&Path>) -> Result<toml::Table> {
    let Some(path) = path else {
        return Ok(toml::Table::new());
    };
    let text = std::fs::read_to_string(path).map_err(|e| HilError::io("reading", path, e))?;
    let table: toml::Table = toml::from_str(&text)
        .map_err(|e| HilError::invalid_input(path.display().to_string(), e.to_string()))?;
    for key in table.keys() {
        if ![
            "linucb",
            "always_query",
            "linucb_qg",
            "workload",
            "environment",
        ]
        .contains(&key.as_str())
        {
            return Err(HilError::invalid_input(
                format!("{}: table `{key}`", path.display()),
                "unknown; expected linucb, always_query, linucb_qg, workload, channel or environment",
            ));
        }
    }
    Ok(table)
}

/// Default policy parameters of the demo (override with `--components`):
/// α = 0.5 for all three, LinUCB-QG workload weight w = 0.3, all
/// pretrained on the environment's simulated pretraining attempts.
fn default_policy(key: &str) -> toml::Value {
    let mut t = toml::Table::new();
    t.insert("type".into(), toml::Value::String(key.into()));
    t.insert("alpha".into(), toml::Value::Float(0.5));
    t.insert("pretrain".into(), toml::Value::Boolean(true));
    if key == "linucb_qg" {
        t.insert("w".into(), toml::Value::Float(0.3));
    }
    toml::Value::Table(t)
}

fn policy_config(table: &toml::Table, key: &str) -> Result<Box<dyn PolicyConfig>> {
    let value = table
        .get(key)
        .cloned()
        .unwrap_or_else(|| default_policy(key));
    value.try_into().map_err(|e: toml::de::Error| {
        HilError::invalid_input(
            format!("policy `{key}`"),
            format!("{e} (is hil-policies built in, with a policy type named `{key}`?)"),
        )
    })
}

/// The participant answering queries: hil-channels' `simulated_expert`
/// (a perfect expert by default) unless `[channel]` says otherwise.
fn channel_config(table: &toml::Table) -> Result<Box<dyn QueryChannelConfig>> {
    let value = table.get("channel").cloned().unwrap_or_else(|| {
        let mut t = toml::Table::new();
        t.insert(
            "type".into(),
            toml::Value::String("simulated_expert".into()),
        );
        toml::Value::Table(t)
    });
    value
        .try_into()
        .map_err(|e: toml::de::Error| HilError::invalid_input("channel", e.to_string()))
}

fn workload_config(table: &toml::Table) -> Result<Box<dyn WorkloadModelConfig>> {
    let value = table.get("workload").cloned().unwrap_or_else(|| {
        let mut t = toml::Table::new();
        t.insert("type".into(), toml::Value::String("bundled".into()));
        t.insert("name".into(), toml::Value::String("f12_real".into()));
        toml::Value::Table(t)
    });
    value.try_into().map_err(|e: toml::de::Error| {
        HilError::invalid_input(
            "workload model",
            format!("{e} (the default is hil-workload's bundled `f12_real`)"),
        )
    })
}

fn demo_kinova(args: KinovaDemoArgs) -> Result<()> {
    if args.repetitions == 0 || args.n_att == 0 {
        return Err(HilError::invalid_parameter(
            "--repetitions/--n-att",
            format!("{}/{}", args.repetitions, args.n_att),
            "must be at least 1",
        ));
    }
    let table = components(args.components.as_deref())?;
    let env_cfg: KinovaFeedingConfig = match table.get("environment") {
        Some(v) => v
            .clone()
            .try_into()
            .map_err(|e: toml::de::Error| HilError::invalid_input("environment", e.to_string()))?,
        None => KinovaFeedingConfig {
            pretraining_trials: 2,
            ..KinovaFeedingConfig::default()
        },
    };
    let mut env = KinovaFeedingEnv::new(env_cfg.clone())?;
    let base = args
        .components
        .as_deref()
        .and_then(Path::parent)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("."));
    let mut ctx = BuildContext::new(&base, args.seed);
    ctx.action_space = Some(env.action_space().clone());
    ctx.context_dim = Some(env.context_dim());
    if !args.quiet && env_cfg.pretraining_trials > 0 {
        eprintln!(
            "simulating {} pretraining attempts per (food, action)",
            env_cfg.pretraining_trials
        );
    }
    ctx.pretraining = hil_core::config::EnvironmentConfig::pretraining(&env_cfg, &ctx)?;
    let workload = workload_config(&table)?.build(&ctx)?;
    let mut policies = Vec::new();
    for (label, key) in METHODS {
        let p = policy_config(&table, key)?
            .build(&ctx)
            .map_err(|e| HilError::invalid_input(format!("policy {label}"), e.to_string()))?;
        policies.push(p);
    }
    let mut writer = match &args.render {
        Some(dir) => match KeyframeWriter::new(dir, env.simulator()) {
            Ok(w) => Some(w),
            Err(why) => {
                eprintln!("note: rendering unavailable ({why}); continuing without pictures");
                None
            }
        },
        None => None,
    };
    let mut recorder = KeyframeRecorder::default();
    let settings = SessionSettings {
        n_att: args.n_att,
        wl0: 0.5,
        max_items: None,
    };
    let mut plates = Vec::new();
    for rep in 0..args.repetitions {
        for (position, &m) in method_order(rep).iter().enumerate() {
            let (label, _) = METHODS[m];
            if !args.quiet {
                eprintln!("repetition {} plate {}: {label}", rep + 1, position + 1);
            }
            let seed = hil_core::session::splitmix(args.seed, (rep * 3 + position) as u64);
            let mut channel = channel_config(&table)?.build(&ctx)?;
            recorder.set_prefix(format!("rep{}_{}", rep + 1, METHODS[m].1));
            let report = {
                let mut render_env;
                let environment: &mut dyn Environment = if writer.is_some() {
                    render_env = RenderingEnv::new(&mut env, &mut recorder);
                    &mut render_env
                } else {
                    &mut env
                };
                let mut session = Session {
                    settings: settings.clone(),
                    environment,
                    policy: policies[m].as_mut(),
                    channel: channel.as_mut(),
                    workload: Arc::clone(&workload),
                    forecast: None,
                };
                session.run_episode(seed, &mut [])?
            };
            if let Some(w) = writer.as_mut() {
                if let Err(why) = w.write(&mut recorder) {
                    eprintln!("note: {why}; continuing without pictures");
                    writer = None;
                }
            }
            plates.push(PlateResult {
                method: label,
                repetition: rep + 1,
                position: position + 1,
                r_task_avg: report.metrics.r_task_avg,
                n_success: report.metrics.n_success,
                n_q: report.metrics.n_q,
                n_steps: report.metrics.n_steps,
            });
        }
    }
    let summary: Vec<MethodSummary> = METHODS
        .iter()
        .map(|(label, _)| {
            let rows: Vec<&PlateResult> = plates.iter().filter(|p| p.method == *label).collect();
            let n = rows.len().max(1) as f64;
            MethodSummary {
                method: label,
                r_task_avg: rows.iter().map(|p| p.r_task_avg).sum::<f64>() / n,
                n_success_per_plate: rows.iter().map(|p| p.n_success as f64).sum::<f64>() / n,
                n_q_per_plate: rows.iter().map(|p| p.n_q as f64).sum::<f64>() / n,
            }
        })
        .collect();
    if args.json {
        let out = serde_json::json!({
            "protocol": {"foods": ["banana", "carrot", "cantaloupe"], "n_att": args.n_att,
                          "repetitions": args.repetitions, "seed": args.seed},
            "plates": plates,
            "methods": summary,
            "note": "MuJoCo simulation of the user-study protocol; food properties are synthetic, calibrated to published success rates",
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("demo report", e))?
        );
    } else {
        println!("User-study protocol in MuJoCo simulation (synthetic food properties).");
        println!(
            "{:<12} {:>4} {:>4} {:>11} {:>10} {:>4}",
            "method", "rep", "pos", "r_task_avg", "n_success", "n_q"
        );
        for p in &plates {
            println!(
                "{:<12} {:>4} {:>4} {:>11.3} {:>10} {:>4}",
                p.method, p.repetition, p.position, p.r_task_avg, p.n_success, p.n_q
            );
        }
        println!("\nper method (mean over plates of 3 items):");
        for s in &summary {
            println!(
                "{:<12} r_task_avg {:.3}  n_success {:.2}  n_q {:.2}",
                s.method, s.r_task_avg, s.n_success_per_plate, s.n_q_per_plate
            );
        }
    }
    if let Some(w) = writer {
        eprintln!("wrote {} keyframes to {}", w.written(), w.dir().display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_order_is_counterbalanced() {
        // Two repetitions: equal mean position for every method.
        let mut sum = [0; 3];
        for rep in 0..2 {
            for (p, &m) in method_order(rep).iter().enumerate() {
                sum[m] += p;
            }
        }
        assert_eq!(sum, [2, 2, 2]);
        // Six repetitions: every method twice in every position.
        let mut pos = [[0; 3]; 3];
        for rep in 0..6 {
            let o = method_order(rep);
            let mut seen = o;
            seen.sort();
            assert_eq!(seen, [0, 1, 2]);
            for (p, &m) in o.iter().enumerate() {
                pos[m][p] += 1;
            }
        }
        assert!(pos.iter().flatten().all(|&c| c == 2));
    }
}
