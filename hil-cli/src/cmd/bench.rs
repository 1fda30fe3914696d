//! `hil bench ...`: reads the arguments, runs a benchmark of
//! [`hil_experiments::bench`] and prints its report. One subcommand per
//! file under `bench/`, each a variant of [`BenchWhat`].

mod policy;
mod reproduce;
mod speech;

use hil_core::Result;

/// Arguments of `hil bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: BenchWhat,
}

#[derive(Debug, clap::Subcommand)]
enum BenchWhat {
    /// Median decide + observe time of a policy at a given scale.
    Policy(policy::PolicyArgs),
    /// Wall time of the full default `hil reproduce`.
    Reproduce(reproduce::ReproduceArgs),
    /// Recognition accuracy, false accepts, re-asks and latency of spoken answers.
    Speech(speech::SpeechBench),
}

/// Runs `hil bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchWhat::Policy(a) => policy::run(a),
        BenchWhat::Reproduce(a) => reproduce::run(a),
        BenchWhat::Speech(a) => speech::run(&a),
    }
}
