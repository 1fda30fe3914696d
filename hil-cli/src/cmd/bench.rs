//! `hil bench ...`: reads the arguments, runs a benchmark of
//! [`hil_experiments::bench`] and prints its report. One subcommand per
//! file under `bench/`, each a variant of [`BenchWhat`].

mod policy;
mod reproduce;

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
}

/// Runs `hil bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchWhat::Policy(a) => policy::run(a),
        BenchWhat::Reproduce(a) => reproduce::run(a),
    }
}
