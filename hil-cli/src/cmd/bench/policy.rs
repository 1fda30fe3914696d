//! `hil bench policy ...`: a policy's decide + observe at scale against the
//! memory-bandwidth floor ([`hil_experiments::bench::PolicyBench`]).

use crate::out::outln;
use std::path::PathBuf;

use hil_core::Result;
use hil_experiments::bench::{PolicyBench, PolicySpec};

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum ReprArg {
    Auto,
    Kernel,
    Dense,
}

impl ReprArg {
    /// The config spelling (`estimator.representation`).
    fn config_name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Kernel => "kernel",
            Self::Dense => "dense",
        }
    }
}

/// Arguments of `hil bench policy`.
#[derive(Debug, clap::Args)]
pub struct PolicyArgs {
    /// Policy config type: a built-in (linucb, always_query,
    /// linucb_exp_decay, linucb_qg) or one a --plugin registers.
    /// Default: the --policy-config file's `type`, else linucb_qg.
    #[arg(long)]
    policy: Option<String>,
    /// Policy parameter as KEY=VALUE (a TOML value; bare words are
    /// strings; dotted keys reach into tables, e.g.
    /// estimator.representation=dense). Repeatable. Built-in policies get
    /// alpha = 0.5, w = 0.2 (linucb_qg), c = 0.1 (linucb_exp_decay) and
    /// pretrain = true unless set.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// A TOML file whose top-level keys are the policy's table (as under
    /// `[policy]` in an experiment config); --policy and --set override it.
    #[arg(long, value_name = "FILE")]
    policy_config: Option<PathBuf>,
    /// Plugin library to load first, so that its policy types can be named.
    /// Repeatable.
    #[arg(long = "plugin", value_name = "PATH")]
    plugins: Vec<PathBuf>,
    /// Context dimension d.
    #[arg(long, default_value_t = 2048)]
    dim: usize,
    /// Number of arms.
    #[arg(long, default_value_t = 6)]
    arms: usize,
    /// Pretraining observations per arm.
    #[arg(long, default_value_t = 300)]
    pretrain: usize,
    /// Timed steps (each one decide + observe).
    #[arg(long, default_value_t = 200)]
    steps: usize,
    /// Estimator representation (built-in policies only; shorthand for
    /// --set estimator.representation=...).
    #[arg(long, value_enum)]
    representation: Option<ReprArg>,
    /// Crossover (fraction of d) for the automatic representation
    /// (built-in policies only; shorthand for --set estimator.crossover=...).
    #[arg(long)]
    crossover: Option<f64>,
    /// Label every pretraining context for every arm (as a dataset that
    /// records all actions per context does) instead of drawing fresh
    /// contexts per arm.
    #[arg(long)]
    shared_contexts: bool,
    /// Seed of the synthetic data, also the policy's seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// Also keep the printed summary as a Markdown results page at this
    /// path (e.g. docs/results/policy-bench-fresh.md), naming this command
    /// line.
    #[arg(long, value_name = "FILE", conflicts_with = "json")]
    write_doc: Option<PathBuf>,
}

pub fn run(a: PolicyArgs) -> Result<()> {
    for path in &a.plugins {
        hil_plugin::load(path)?;
    }
    let bench = PolicyBench {
        spec: PolicySpec {
            policy: a.policy,
            file: a.policy_config,
            sets: a.sets,
            representation: a.representation.map(|r| r.config_name().to_string()),
            crossover: a.crossover,
        },
        dim: a.dim,
        arms: a.arms,
        pretrain: a.pretrain,
        steps: a.steps,
        shared_contexts: a.shared_contexts,
        seed: a.seed,
        probe_bytes: 0,
    };
    let report = bench.run()?;
    if a.json {
        return outln!("{}", report.to_json(&bench));
    }
    crate::cmd::emit_report(
        &format!("{}\n", report.summary(&bench)),
        a.write_doc.as_deref(),
        "A policy's decide + observe against the memory-bandwidth floor",
    )
}
