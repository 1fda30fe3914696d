//! `hil bench policy ...`: time a policy's decide + observe at scale;
//! `hil bench reproduce`: time the README's main job.
//!
//! Contexts and rewards are synthetic (random unit-scale vectors, rewards
//! drawn from a hidden linear model); the point is the cost of the
//! estimator, which does not depend on what the numbers mean.
//!
//! The policy is built through its `PolicyConfig` (`--policy TYPE`,
//! `--set key=value`, `--policy-config FILE`, `--plugin PATH`), so any
//! built-in or plugin policy type can be timed; the synthetic pretraining
//! data reaches it as the environment's pretraining data would. Memory
//! traffic (bytes per step, the bandwidth floor) is known only for the
//! built-in estimator and is reported as absent for other policies.

use hil_config::TaskContext;
use hil_core::WorkloadInput;
mod reproduce;
mod spec;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use hil_config::BuildContext;
use hil_core::{
    ActionSpace, ArmId, Choice, Context, DecisionInput, Feedback, HilError, LabelledObservation,
    QueryHistory, Result, Timestep, WorkloadForecast, WorkloadModel,
};
use hil_policies::{EstimatorConfig, LinearArms, Representation};
use hil_stats::{median, quantile};
use serde_json::json;

use spec::PolicySpec;

/// Arguments of `hil bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: BenchWhat,
}

#[derive(Debug, clap::Subcommand)]
enum BenchWhat {
    /// Median decide + observe time of a policy at a given scale.
    Policy(PolicyBench),
    /// Wall time of the full default `hil reproduce`.
    Reproduce(reproduce::ReproduceBench),
}

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

#[derive(Debug, clap::Args)]
struct PolicyBench {
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
}

/// Runs `hil bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchWhat::Policy(p) => bench_policy(&p),
        BenchWhat::Reproduce(r) => reproduce::bench_reproduce(&r),
    }
}

/// SplitMix64: enough randomness for synthetic benchmark data.
struct Mix(u64);

impl Mix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn context(&mut self, d: usize) -> Context {
        let s = (3.0 / d as f64).sqrt(); // unit expected norm
        let v: Vec<f64> = (0..d).map(|_| (2.0 * self.unit() - 1.0) * s).collect();
        Context::new(v).expect("finite by construction")
    }
}

/// WL_t = min(1, WL_0 + 0.05 · queries so far): a stand-in forecast so
/// LinUCB-QG pays for its workload query as it would in a session.
struct PerQuery;

impl WorkloadModel for PerQuery {
    fn name(&self) -> &str {
        "per_query"
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        let n = input.history.count_until(input.t);
        Ok((input.wl0 + 0.05 * n as f64).min(1.0))
    }
}

fn bench_policy(a: &PolicyBench) -> Result<()> {
    if a.steps == 0 || a.arms == 0 || a.dim == 0 {
        return Err(HilError::invalid_input(
            "bench arguments",
            "--steps, --arms and --dim must be at least 1",
        ));
    }
    for path in &a.plugins {
        hil_plugin::load(path)?;
    }
    let spec = PolicySpec {
        policy: a.policy.clone(),
        file: a.policy_config.clone(),
        sets: a.sets.clone(),
        representation: a.representation.map(|r| r.config_name().to_string()),
        crossover: a.crossover,
    };
    let table = spec.table()?;
    // Before the data are drawn: a bad setting fails at once.
    let config = spec::parse(&table)?;
    let mut rng = Mix(a.seed);
    // Hidden linear reward model, one weight vector per arm.
    let truth: Vec<Context> = (0..a.arms).map(|_| rng.context(a.dim)).collect();
    let p_success = |x: &Context, arm: usize| -> f64 {
        let s: f64 = x.iter().zip(truth[arm].iter()).map(|(p, q)| p * q).sum();
        1.0 / (1.0 + (-4.0 * s).exp())
    };
    let mut data = Vec::with_capacity(a.pretrain * a.arms);
    for _ in 0..a.pretrain {
        let shared = rng.context(a.dim);
        for arm in 0..a.arms {
            let x = if a.shared_contexts {
                shared.clone()
            } else {
                rng.context(a.dim)
            };
            let reward = f64::from(rng.unit() < p_success(&x, arm));
            data.push(LabelledObservation {
                context: x,
                arm: ArmId(arm),
                reward,
            });
        }
    }
    let ctx = TaskContext::new(
        BuildContext::new(".", a.seed),
        ActionSpace::new((0..a.arms).map(|i| format!("arm{i}")))?,
        a.dim,
    )
    .with_pretraining(Arc::from(data));

    let t0 = Instant::now();
    let mut policy = config.build(&ctx)?;
    let pretrain_s = t0.elapsed().as_secs_f64();
    policy.seed(a.seed);
    // The built-in policies' memory traffic, read off a twin of their
    // estimator: same options and data, so the build context's memo hands
    // back the estimator the policy was built from (no second pretraining).
    let traffic = match EstimatorConfig::from_policy_table(&table)? {
        Some(est) => Some(Traffic::of(&est.build_estimator(&ctx)?)?),
        None => None,
    };
    drop(ctx);

    // Read bandwidth is sampled between steps, so that the floor sees the
    // same machine load as the steps do (this machine is shared). Without
    // a traffic figure there is no floor to compare with, so no probe.
    let bw_buf: Vec<f64> = if traffic.is_some() {
        (0..BW_LEN).map(|i| (i % 7) as f64).collect()
    } else {
        Vec::new()
    };
    let mut bw_samples = Vec::new();
    let model = PerQuery;
    let mut history = QueryHistory::new();
    let warmup = 3.min(a.steps);
    let mut step_us = Vec::with_capacity(a.steps);
    let mut decide_us = Vec::with_capacity(a.steps);
    let mut queries = 0usize;
    for s in 0..(a.steps + warmup) {
        if s % 20 == 0 && !bw_buf.is_empty() {
            bw_samples.push(read_bandwidth(&bw_buf));
        }
        let x = rng.context(a.dim);
        let t = s as Timestep + 1;
        let input =
            DecisionInput::new(&x, t, WorkloadForecast::new(Some(&model), 0.5, &history, t))
                .at_item(s, s, 0);
        let start = Instant::now();
        let d = policy.decide(&input)?;
        let mid = Instant::now();
        // The simulated expert answers with the truly best arm.
        let (arm, expert) = match d.choice {
            Choice::Act { arm } => (arm, false),
            Choice::Query { .. } => {
                let best = (0..a.arms)
                    .max_by(|&i, &j| p_success(&x, i).total_cmp(&p_success(&x, j)))
                    .unwrap_or(0);
                (ArmId(best), true)
            }
        };
        let reward = f64::from(rng.unit() < p_success(&x, arm.0));
        let mid2 = Instant::now();
        let attempt = hil_core::Attempt {
            context: &x,
            arm,
            reward,
            t,
        };
        policy.observe(&Feedback::new(attempt).from_expert(expert))?;
        let end = Instant::now();
        if let Choice::Query { kind, .. } = d.choice {
            history.push(t, kind)?;
        }
        if s >= warmup {
            queries += usize::from(expert);
            let total = (mid - start) + (end - mid2);
            step_us.push(total.as_secs_f64() * 1e6);
            decide_us.push((mid - start).as_secs_f64() * 1e6);
        }
    }
    let per_step_us = median(&step_us);
    let decide_median = median(&decide_us);
    let bw = (!bw_buf.is_empty()).then(|| {
        bw_samples.push(read_bandwidth(&bw_buf));
        median(&bw_samples)
    });
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_default();
    let pct = |p: f64| quantile(&step_us, p);
    let floors = traffic
        .zip(bw)
        .map(|(tr, bw)| Floors::new(&tr, bw, per_step_us, pct(0.1)));
    let out = json!({
        "policy": policy.name(),
        "dim": a.dim,
        "arms": a.arms,
        "pretrain_per_arm": a.pretrain,
        "shared_contexts": a.shared_contexts,
        "steps": a.steps,
        "representation": traffic.map(|t| t.representation),
        "per_step_us": per_step_us,
        "p10_step_us": pct(0.1),
        "p90_step_us": pct(0.9),
        "decide_us": decide_median,
        "observe_us": per_step_us - decide_median,
        "pretrain_s": pretrain_s,
        "queries": queries,
        "bytes_per_step": traffic.map(|t| t.bytes_read),
        "read_bandwidth_gb_s": bw.map(|bw| bw / 1e9),
        "bandwidth_floor_us": floors.map(|f| f.floor_us),
        "ratio_to_floor": floors.map(|f| f.ratio),
        "p10_ratio_to_floor": floors.map(|f| f.p10_ratio),
        "bytes_written_per_step": traffic.map(|t| t.bytes_written),
        "floor_with_writes_us": floors.map(|f| f.floor_with_writes_us),
        "ratio_to_floor_with_writes": floors.map(|f| f.ratio_with_writes),
        "bandwidth_samples": bw_samples.len(),
        "load_average_1m": load,
        "data": "synthetic",
    });
    if a.json {
        println!("{out}");
        return Ok(());
    }
    let memory = match (traffic, floors) {
        (Some(t), Some(f)) => format!(
            "{} bytes/step, read bandwidth {:.2} GB/s, floor {:.1} µs, ratio {:.2}",
            t.bytes_read,
            f.bandwidth / 1e9,
            f.floor_us,
            f.ratio
        ),
        _ => "memory traffic n/a (not the built-in estimator)".to_string(),
    };
    println!(
        "{} d={} arms={} pretrain/arm={} ({}): median decide+observe {:.1} µs \
         (p10 {:.1}, p90 {:.1}); {memory}; pretraining {:.2} s; load {}; synthetic data",
        policy.name(),
        a.dim,
        a.arms,
        a.pretrain,
        traffic.map_or("representation n/a", |t| t.representation),
        per_step_us,
        pct(0.1),
        pct(0.9),
        pretrain_s,
        load
    );
    Ok(())
}

/// What one step of the built-in estimator reads and writes.
#[derive(Clone, Copy, Debug)]
struct Traffic {
    /// `kernel`, `dense` or `mixed` (over the arms).
    representation: &'static str,
    /// Bytes read by one score of every arm plus one update.
    bytes_read: usize,
    /// Bytes one update writes.
    bytes_written: usize,
}

impl Traffic {
    fn of(arms: &LinearArms) -> Result<Self> {
        let reprs: Vec<Representation> = (0..arms.n_arms())
            .map(|i| arms.representation(ArmId(i)))
            .collect::<Result<_>>()?;
        let representation = if reprs.iter().all(|r| *r == Representation::Kernel) {
            "kernel"
        } else if reprs.iter().all(|r| *r == Representation::Dense) {
            "dense"
        } else {
            "mixed"
        };
        let bytes_per_update = arms.bytes_per_update(ArmId(0))?;
        // A dense update rewrites the factor it read; a kernel update appends O(n).
        let bytes_written = match arms.representation(ArmId(0))? {
            Representation::Dense => bytes_per_update,
            Representation::Kernel => 0,
        };
        Ok(Self {
            representation,
            bytes_read: arms.bytes_per_score() + bytes_per_update,
            bytes_written,
        })
    }
}

/// The bandwidth floors of a step and the measured times relative to them.
#[derive(Clone, Copy, Debug)]
struct Floors {
    bandwidth: f64,
    floor_us: f64,
    ratio: f64,
    p10_ratio: f64,
    floor_with_writes_us: f64,
    ratio_with_writes: f64,
}

impl Floors {
    fn new(t: &Traffic, bandwidth: f64, median_us: f64, p10_us: f64) -> Self {
        let floor_us = t.bytes_read as f64 / bandwidth * 1e6;
        let floor_with_writes_us = (t.bytes_read + t.bytes_written) as f64 / bandwidth * 1e6;
        Self {
            bandwidth,
            floor_us,
            ratio: median_us / floor_us,
            p10_ratio: p10_us / floor_us,
            floor_with_writes_us,
            ratio_with_writes: median_us / floor_with_writes_us,
        }
    }
}

/// Length of the bandwidth probe: 256 MiB of f64, far beyond any
/// last-level cache.
const BW_LEN: usize = 32 << 20;

/// Single-thread read bandwidth in bytes/s: the faster of two sums over
/// `buf` (the first may still be warming the TLB).
fn read_bandwidth(buf: &[f64]) -> f64 {
    let mut best = f64::INFINITY;
    let mut sink = 0.0;
    for _ in 0..2 {
        let t = Instant::now();
        let mut acc = [0.0f64; 8];
        for c in buf.chunks_exact(8) {
            for k in 0..8 {
                acc[k] += c[k];
            }
        }
        sink += acc.iter().sum::<f64>();
        best = best.min(t.elapsed().as_secs_f64());
    }
    std::hint::black_box(sink);
    std::mem::size_of_val(buf) as f64 / best
}
