//! `hil`: run human-in-the-loop contextual-bandit experiments.

mod cmd;
mod out;
#[cfg(not(feature = "speech"))]
mod speech_unavailable;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Human-in-the-loop contextual bandits for assistive robotics.
///
/// A robot chooses an action for each item (a food piece on a plate) or asks
/// the person it serves, trading task success against querying workload.
/// Bundled data is synthetic, calibrated to published figures.
#[derive(Debug, Parser)]
#[command(name = "hil", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run an experiment described by a TOML config.
    Run(cmd::run::RunArgs),
    /// Rerun the paper's simulated experiments: results.json, tables.md, SVG figures.
    Reproduce(cmd::reproduce::ReproduceArgs),
    /// Generate or check food datasets.
    Data(cmd::data::DataArgs),
    /// Demonstrations (`hil demo kinova`: the user study in MuJoCo).
    Demo(cmd::kinova::DemoArgs),
    /// The MuJoCo Kinova Gen3 feeding simulation (`hil kinova calibrate`).
    Kinova(cmd::kinova::KinovaArgs),
    /// Benchmark components (e.g. `hil bench policy --policy linucb_qg`).
    Bench(cmd::bench::BenchArgs),
    /// Workload study data and models: generate, select, fit, rollout, bundle.
    Workload(cmd::workload::WorkloadArgs),
    /// The workload study in the browser: serve it, follow progress, export the CSV.
    Study(cmd::study::StudyArgs),
    /// Inspect plugin libraries and check their types for conformance.
    Plugins(cmd::plugins::PluginsArgs),
    /// Interaction logs: make a key for keyed logs, verify a log's chain.
    Record(cmd::record::RecordArgs),
}

fn main() -> ExitCode {
    // Every built-in component type is registered: this binary uses
    // hil_experiments, which links them all (hil_experiments::builtin).
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => cmd::run::run(args),
        Command::Reproduce(args) => cmd::reproduce::run(args),
        Command::Data(args) => cmd::data::run(args),
        Command::Demo(args) => cmd::kinova::demo(args),
        Command::Kinova(args) => cmd::kinova::kinova(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Workload(args) => cmd::workload::run(args),
        Command::Study(args) => cmd::study::run(args),
        Command::Plugins(args) => cmd::plugins::run(args),
        Command::Record(args) => cmd::record::run(args),
    };
    // Every command has dropped its components by now: a plugin object
    // whose destructor panicked (in `hil reproduce`, `hil demo`, ...) fails
    // the command instead of passing unnoticed.
    let result = cmd::plugins::with_destructor_panics(result);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that has gone (`hil data check DIR | head -3`) is no
        // error of ours: end quietly, as a program that SIGPIPE ends.
        Err(e) if out::is_closed_stdout(&e) => ExitCode::from(out::CLOSED_STDOUT_STATUS),
        Err(e) => {
            out::note!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
