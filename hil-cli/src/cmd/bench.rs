//! `hil bench policy ...`: time a policy's decide + observe at scale.
//!
//! Contexts and rewards are synthetic (random unit-scale vectors, rewards
//! drawn from a hidden linear model); the point is the cost of the
//! estimator, which does not depend on what the numbers mean.

use std::time::Instant;

use hil_core::{
    ArmId, Choice, Context, DecisionInput, Feedback, HilError, LabelledObservation, Policy,
    QueryHistory, QueryKind, Result, Timestep, WorkloadForecast, WorkloadModel,
};
use hil_policies::{
    AlwaysQuery, AlwaysQueryParams, EstimatorOptions, LinUcb, LinUcbExpDecay, LinUcbExpDecayParams,
    LinUcbParams, LinUcbQg, LinUcbQgParams, LinearArms, Representation, RepresentationChoice,
};
use serde_json::json;

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
}

#[derive(Debug, Clone, Copy)]
enum PolicyName {
    Linucb,
    AlwaysQuery,
    LinucbExpDecay,
    LinucbQg,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum ReprArg {
    Auto,
    Kernel,
    Dense,
}

#[derive(Debug, clap::Args)]
struct PolicyBench {
    /// Which policy.
    #[arg(long, default_value = "linucb_qg", value_parser = parse_policy)]
    policy: PolicyName,
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
    /// Estimator representation.
    #[arg(long, value_enum, default_value = "auto")]
    representation: ReprArg,
    /// Crossover (fraction of d) for the automatic representation.
    #[arg(long)]
    crossover: Option<f64>,
    /// Label every pretraining context for every arm (as a dataset that
    /// records all actions per context does) instead of drawing fresh
    /// contexts per arm.
    #[arg(long)]
    shared_contexts: bool,
    /// Confidence weight α.
    #[arg(long, default_value_t = 0.5)]
    alpha: f64,
    /// Ridge strength λ.
    #[arg(long, default_value_t = 1.0)]
    lambda: f64,
    /// Workload weight w (LinUCB-QG).
    #[arg(long, default_value_t = 0.2)]
    w: f64,
    /// Decay rate c (LinUCB-ExpDecay).
    #[arg(long, default_value_t = 0.1)]
    c: f64,
    /// Seed of the synthetic data.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

fn parse_policy(s: &str) -> std::result::Result<PolicyName, String> {
    match s {
        "linucb" => Ok(PolicyName::Linucb),
        "always_query" | "always-query" => Ok(PolicyName::AlwaysQuery),
        "linucb_exp_decay" | "linucb-exp-decay" => Ok(PolicyName::LinucbExpDecay),
        "linucb_qg" | "linucb-qg" => Ok(PolicyName::LinucbQg),
        _ => Err(format!(
            "unknown policy `{s}` (expected linucb, always_query, linucb_exp_decay or linucb_qg)"
        )),
    }
}

/// Runs `hil bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchWhat::Policy(p) => bench_policy(&p),
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
    fn predict(&self, wl0: f64, h: &QueryHistory, t: Timestep) -> Result<f64> {
        let n = h.records().iter().filter(|r| r.t <= t).count();
        Ok((wl0 + 0.05 * n as f64).min(1.0))
    }
}

fn bench_policy(a: &PolicyBench) -> Result<()> {
    if a.steps == 0 || a.arms == 0 || a.dim == 0 {
        return Err(HilError::invalid_input(
            "bench arguments",
            "--steps, --arms and --dim must be at least 1",
        ));
    }
    let mut rng = Mix(a.seed);
    // Hidden linear reward model, one weight vector per arm.
    let truth: Vec<Context> = (0..a.arms).map(|_| rng.context(a.dim)).collect();
    let p_success = |x: &Context, arm: usize| -> f64 {
        let s: f64 = x.iter().zip(truth[arm].iter()).map(|(p, q)| p * q).sum();
        1.0 / (1.0 + (-4.0 * s).exp())
    };
    let mut data = Vec::with_capacity(a.pretrain * a.arms);
    let shared: Vec<Context> = if a.shared_contexts {
        (0..a.pretrain).map(|_| rng.context(a.dim)).collect()
    } else {
        Vec::new()
    };
    for i in 0..a.pretrain {
        for arm in 0..a.arms {
            let x = if a.shared_contexts {
                shared[i].clone()
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
    let mut options = EstimatorOptions {
        representation: match a.representation {
            ReprArg::Auto => RepresentationChoice::Auto,
            ReprArg::Kernel => RepresentationChoice::Kernel,
            ReprArg::Dense => RepresentationChoice::Dense,
        },
        ..Default::default()
    };
    if let Some(c) = a.crossover {
        options.crossover = c;
    }
    let t0 = Instant::now();
    let mut arms = LinearArms::with_options(a.arms, a.dim, a.lambda, options)?;
    arms.pretrain(&data)?;
    let pretrain_s = t0.elapsed().as_secs_f64();
    drop(data);

    let reprs: Vec<Representation> = (0..a.arms)
        .map(|i| arms.representation(ArmId(i)))
        .collect::<Result<_>>()?;
    let representation = if reprs.iter().all(|r| *r == Representation::Kernel) {
        "kernel"
    } else if reprs.iter().all(|r| *r == Representation::Dense) {
        "dense"
    } else {
        "mixed"
    };
    let bytes_per_score = arms.bytes_per_score();
    let bytes_per_update = arms.bytes_per_update(ArmId(0))?;

    let kind = QueryKind::default();
    let mut policy: Box<dyn Policy> = match a.policy {
        PolicyName::Linucb => Box::new(LinUcb::new(LinUcbParams::new(a.alpha)?, arms)),
        PolicyName::AlwaysQuery => Box::new(AlwaysQuery::new(
            AlwaysQueryParams::new(a.alpha, kind)?,
            arms,
        )),
        PolicyName::LinucbExpDecay => Box::new(LinUcbExpDecay::new(
            LinUcbExpDecayParams::new(a.alpha, a.c, kind)?,
            arms,
        )),
        PolicyName::LinucbQg => Box::new(LinUcbQg::new(
            LinUcbQgParams::new(a.alpha, a.w, kind)?,
            arms,
        )),
    };
    policy.seed(a.seed);

    let model = PerQuery;
    let mut history = QueryHistory::new();
    let warmup = 3.min(a.steps);
    let mut step_us = Vec::with_capacity(a.steps);
    let mut decide_us = Vec::with_capacity(a.steps);
    let mut queries = 0usize;
    for s in 0..(a.steps + warmup) {
        let x = rng.context(a.dim);
        let t = s as Timestep + 1;
        let input = DecisionInput {
            context: &x,
            t,
            item_index: s,
            items_seen: s,
            attempt: 0,
            workload: WorkloadForecast::new(Some(&model), 0.5, &history, t),
        };
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
        policy.observe(&Feedback {
            context: &x,
            arm,
            reward,
            t,
            from_expert: expert,
        })?;
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
    let per_step_us = median(&mut step_us.clone());
    let decide_median = median(&mut decide_us);
    let bytes_per_step = bytes_per_score + bytes_per_update;
    let bw = read_bandwidth();
    let floor_us = bytes_per_step as f64 / bw * 1e6;
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_default();
    let mut sorted = step_us.clone();
    sorted.sort_by(f64::total_cmp);
    let pct = |p: f64| sorted[((sorted.len() - 1) as f64 * p).round() as usize];
    let out = json!({
        "policy": policy.name(),
        "dim": a.dim,
        "arms": a.arms,
        "pretrain_per_arm": a.pretrain,
        "shared_contexts": a.shared_contexts,
        "steps": a.steps,
        "representation": representation,
        "per_step_us": per_step_us,
        "p10_step_us": pct(0.1),
        "p90_step_us": pct(0.9),
        "decide_us": decide_median,
        "observe_us": per_step_us - decide_median,
        "pretrain_s": pretrain_s,
        "queries": queries,
        "bytes_per_step": bytes_per_step,
        "read_bandwidth_gb_s": bw / 1e9,
        "bandwidth_floor_us": floor_us,
        "ratio_to_floor": per_step_us / floor_us,
        "load_average_1m": load,
        "data": "synthetic",
    });
    if a.json {
        println!("{out}");
    } else {
        println!(
            "{} d={} arms={} pretrain/arm={} ({}): median decide+observe {:.1} µs \
             (p10 {:.1}, p90 {:.1}); {} bytes/step, read bandwidth {:.2} GB/s, \
             floor {:.1} µs, ratio {:.2}; pretraining {:.2} s; load {}; synthetic data",
            policy.name(),
            a.dim,
            a.arms,
            a.pretrain,
            representation,
            per_step_us,
            pct(0.1),
            pct(0.9),
            bytes_per_step,
            bw / 1e9,
            floor_us,
            per_step_us / floor_us,
            pretrain_s,
            load
        );
    }
    Ok(())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Single-thread read bandwidth in bytes/s: the best of several sums over a
/// 256 MiB buffer (far beyond any cache), measured in this run so that the
/// floor reflects the machine's current load.
fn read_bandwidth() -> f64 {
    let n = 32 << 20; // 32 Mi f64 = 256 MiB
    let buf: Vec<f64> = (0..n).map(|i| (i % 7) as f64).collect();
    let mut best = f64::INFINITY;
    let mut sink = 0.0;
    for _ in 0..5 {
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
    (n * std::mem::size_of::<f64>()) as f64 / best
}
