//! A policy's decide + observe at scale, against the memory-bandwidth floor.
//!
//! Contexts and rewards are synthetic (random unit-scale vectors, rewards
//! drawn from a hidden linear model); the point is the cost of the
//! estimator, which does not depend on what the numbers mean.
//!
//! The policy is built through its `PolicyConfig` ([`PolicySpec`]), so any
//! built-in or plugin policy type can be timed; the synthetic pretraining
//! data reaches it as the environment's pretraining data would. Memory
//! traffic (bytes per step, the bandwidth floor) is known only for the
//! built-in estimator and is reported as absent for other policies.

use std::sync::Arc;
use std::time::Instant;

use hil_config::{BuildContext, TaskContext};
use hil_core::{
    ActionSpace, ArmId, Choice, Context, DecisionInput, Feedback, HilError, LabelledObservation,
    QueryHistory, Result, Timestep, WorkloadForecast, WorkloadInput, WorkloadModel,
};
use hil_policies::{EstimatorConfig, LinearArms, Representation};
use hil_stats::{median, quantile};
use serde_json::json;

use super::spec::{self, PolicySpec};

/// What to time: the policy and the scale.
#[derive(Debug, Default)]
pub struct PolicyBench {
    /// The policy (type, settings).
    pub spec: PolicySpec,
    /// Context dimension d.
    pub dim: usize,
    /// Number of arms.
    pub arms: usize,
    /// Pretraining observations per arm.
    pub pretrain: usize,
    /// Timed steps (each one decide + observe).
    pub steps: usize,
    /// Label every pretraining context for every arm instead of drawing
    /// fresh contexts per arm.
    pub shared_contexts: bool,
    /// Seed of the synthetic data, also the policy's seed.
    pub seed: u64,
    /// Bytes read by each bandwidth probe (0: the default, 256 MiB, far
    /// beyond any last-level cache).
    pub probe_bytes: usize,
}

/// What one step of the built-in estimator reads and writes, over the
/// timed steps. The estimator grows as it learns (one observation per
/// step, and one stored row per fresh context), so the figures are means
/// over the steps, each step counted at the state it ran on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traffic {
    /// `kernel`, `dense` or `mixed` (over the arms, before the first step).
    pub representation: &'static str,
    /// Bytes read by one score of every arm plus one update (mean).
    pub bytes_read: usize,
    /// Bytes read by the first and by the last timed step.
    pub bytes_read_range: (usize, usize),
    /// Bytes one update writes (mean).
    pub bytes_written: usize,
}

/// The bandwidth floors of a step and the measured times relative to them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Floors {
    /// Measured single-thread read bandwidth, bytes/s (median of the probes).
    pub bandwidth: f64,
    /// Bytes read per step at that bandwidth, µs.
    pub floor_us: f64,
    /// Median step time / floor.
    pub ratio: f64,
    /// 10th-percentile step time / floor.
    pub p10_ratio: f64,
    /// Bytes read and written per step at that bandwidth, µs.
    pub floor_with_writes_us: f64,
    /// Median step time / floor with writes.
    pub ratio_with_writes: f64,
}

/// The result of [`PolicyBench::run`].
#[derive(Clone, Debug, PartialEq)]
pub struct PolicyBenchReport {
    /// The policy's name.
    pub policy: String,
    /// Median decide + observe time, µs.
    pub per_step_us: f64,
    /// 10th and 90th percentiles of the step time, µs.
    pub p10_step_us: f64,
    /// 90th percentile of the step time, µs.
    pub p90_step_us: f64,
    /// Median decide time, µs.
    pub decide_us: f64,
    /// Pretraining (policy build) time, s.
    pub pretrain_s: f64,
    /// Steps that queried the simulated expert.
    pub queries: usize,
    /// Memory traffic (built-in estimator only).
    pub traffic: Option<Traffic>,
    /// The floors (built-in estimator only).
    pub floors: Option<Floors>,
    /// Bandwidth probes taken.
    pub bandwidth_samples: usize,
    /// The 1-minute load average at the end.
    pub load_average_1m: String,
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

/// Default length of the bandwidth probe: 256 MiB.
const PROBE_BYTES: usize = 256 << 20;

/// Most pretraining rounds a policy benchmark takes.
pub const MAX_PRETRAIN: u64 = 1_000_000;
/// Most timed steps a policy benchmark takes.
pub const MAX_STEPS: u64 = 10_000_000;
/// Most numbers one kind of per-arm state (arms × dim², a d × d matrix per
/// arm) or the synthetic pretraining data (rounds × arms × dim) may hold:
/// 2 GiB of `f64` each.
pub const MAX_VALUES: u64 = 1 << 28;

impl PolicyBench {
    /// Checks every size against its limit before anything is allocated,
    /// naming the flag: a 20-digit `--dim` is an error, not a capacity
    /// overflow.
    fn check_sizes(&self) -> Result<()> {
        use hil_config::limits::{ARMS, CONTEXT_DIM, check_at_most, check_count};
        // The estimator's own limits, checked here too so the error names the flag.
        check_count("--dim", self.dim, CONTEXT_DIM)?;
        check_count("--arms", self.arms, ARMS)?;
        check_count("--steps", self.steps, MAX_STEPS)?;
        check_at_most("--pretrain", self.pretrain, MAX_PRETRAIN)?;
        // Each factor is bounded above, so the products cannot overflow.
        let (dim, arms, pretrain) = (self.dim as u64, self.arms as u64, self.pretrain as u64);
        let too_many = |flag: &str, value: u64, what: String, values: u64| {
            HilError::invalid_parameter(
                flag,
                value,
                format!(
                    "{what} is {values} numbers, at most {MAX_VALUES} (2 GiB): \
                     lower --arms or --dim{}",
                    if flag == "--pretrain" {
                        " or --pretrain"
                    } else {
                        ""
                    }
                ),
            )
        };
        let state = arms * dim * dim;
        if state > MAX_VALUES {
            let what = format!("a {dim} × {dim} matrix for each of {arms} arms");
            return Err(too_many("--dim", dim, what, state));
        }
        let data = pretrain * arms * dim;
        if data > MAX_VALUES {
            let what =
                format!("{pretrain} rounds × {arms} arms × dimension {dim} of pretraining data");
            return Err(too_many("--pretrain", pretrain, what, data));
        }
        Ok(())
    }

    /// Builds the policy on synthetic pretraining data, then times `steps`
    /// decide + observe calls (after 3 warm-up steps), sampling the read
    /// bandwidth every 20 steps so that the floor sees the same machine
    /// load as the steps do.
    pub fn run(&self) -> Result<PolicyBenchReport> {
        self.check_sizes()?;
        let table = self.spec.table()?;
        // Before the data are drawn: a bad setting fails at once.
        let config = spec::parse(&table)?;
        let mut rng = Mix(self.seed);
        // Hidden linear reward model, one weight vector per arm.
        let truth: Vec<Context> = (0..self.arms).map(|_| rng.context(self.dim)).collect();
        let p_success = |x: &Context, arm: usize| -> f64 {
            let s: f64 = x.iter().zip(truth[arm].iter()).map(|(p, q)| p * q).sum();
            1.0 / (1.0 + (-4.0 * s).exp())
        };
        let mut data = Vec::with_capacity(self.pretrain * self.arms);
        for _ in 0..self.pretrain {
            let shared = rng.context(self.dim);
            for arm in 0..self.arms {
                let x = if self.shared_contexts {
                    shared.clone()
                } else {
                    rng.context(self.dim)
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
            BuildContext::new(".", self.seed),
            ActionSpace::new((0..self.arms).map(|i| format!("arm{i}")))?,
            self.dim,
        )
        .with_pretraining(Arc::from(data));

        let t0 = Instant::now();
        let mut policy = config.build(&ctx)?;
        let pretrain_s = t0.elapsed().as_secs_f64();
        policy.seed(self.seed);
        // The built-in policies' memory traffic, read off a twin of their
        // estimator: same options and data, so the build context's memo
        // hands back the estimator the policy was built from (no second
        // pretraining). The twin is fed the policy's observations after the
        // clock stops (see `Traffic::over`).
        let twin = match EstimatorConfig::from_policy_table(&table)? {
            Some(est) => Some(est.build_estimator(&ctx)?),
            None => None,
        };
        drop(ctx);

        // Without a traffic figure there is no floor to compare with, so no
        // probe.
        let probe_len = if self.probe_bytes == 0 {
            PROBE_BYTES
        } else {
            self.probe_bytes
        } / std::mem::size_of::<f64>();
        let bw_buf: Vec<f64> = if twin.is_some() {
            (0..probe_len).map(|i| (i % 7) as f64).collect()
        } else {
            Vec::new()
        };
        let mut bw_samples = Vec::new();
        let model = PerQuery;
        let mut history = QueryHistory::new();
        let warmup = 3.min(self.steps);
        let mut step_us = Vec::with_capacity(self.steps);
        let mut decide_us = Vec::with_capacity(self.steps);
        let mut queries = 0usize;
        let mut observed = Vec::with_capacity(if twin.is_some() {
            self.steps + warmup
        } else {
            0
        });
        for s in 0..(self.steps + warmup) {
            if s % 20 == 0 && !bw_buf.is_empty() {
                bw_samples.push(read_bandwidth(&bw_buf));
            }
            let x = rng.context(self.dim);
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
                    let best = (0..self.arms)
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
            if twin.is_some() {
                observed.push((x, arm, reward));
            }
            if s >= warmup {
                queries += usize::from(expert);
                let total = (mid - start) + (end - mid2);
                step_us.push(total.as_secs_f64() * 1e6);
                decide_us.push((mid - start).as_secs_f64() * 1e6);
            }
        }
        let per_step_us = median(&step_us);
        let p10_step_us = quantile(&step_us, 0.1);
        let bw = (!bw_buf.is_empty()).then(|| {
            bw_samples.push(read_bandwidth(&bw_buf));
            median(&bw_samples)
        });
        let traffic = match twin {
            Some(twin) => Some(Traffic::over(twin, &observed, warmup)?),
            None => None,
        };
        let floors = traffic
            .zip(bw)
            .map(|(tr, bw)| Floors::new(&tr, bw, per_step_us, p10_step_us));
        Ok(PolicyBenchReport {
            policy: policy.name().to_string(),
            per_step_us,
            p10_step_us,
            p90_step_us: quantile(&step_us, 0.9),
            decide_us: median(&decide_us),
            pretrain_s,
            queries,
            traffic,
            floors,
            bandwidth_samples: bw_samples.len(),
            load_average_1m: super::load_average_1m(),
        })
    }
}

impl PolicyBenchReport {
    /// The report as `hil bench policy --json` prints it; `bench` names
    /// the scale it was run at.
    pub fn to_json(&self, bench: &PolicyBench) -> serde_json::Value {
        let traffic = self.traffic;
        let floors = self.floors;
        json!({
            "policy": self.policy,
            "dim": bench.dim,
            "arms": bench.arms,
            "pretrain_per_arm": bench.pretrain,
            "shared_contexts": bench.shared_contexts,
            "steps": bench.steps,
            "representation": traffic.map(|t| t.representation),
            "per_step_us": self.per_step_us,
            "p10_step_us": self.p10_step_us,
            "p90_step_us": self.p90_step_us,
            "decide_us": self.decide_us,
            "observe_us": self.per_step_us - self.decide_us,
            "pretrain_s": self.pretrain_s,
            "queries": self.queries,
            "bytes_per_step": traffic.map(|t| t.bytes_read),
            "bytes_per_step_first": traffic.map(|t| t.bytes_read_range.0),
            "bytes_per_step_last": traffic.map(|t| t.bytes_read_range.1),
            "read_bandwidth_gb_s": floors.map(|f| f.bandwidth / 1e9),
            "bandwidth_floor_us": floors.map(|f| f.floor_us),
            "ratio_to_floor": floors.map(|f| f.ratio),
            "p10_ratio_to_floor": floors.map(|f| f.p10_ratio),
            "bytes_written_per_step": traffic.map(|t| t.bytes_written),
            "floor_with_writes_us": floors.map(|f| f.floor_with_writes_us),
            "ratio_to_floor_with_writes": floors.map(|f| f.ratio_with_writes),
            "bandwidth_samples": self.bandwidth_samples,
            "load_average_1m": self.load_average_1m,
            "data": "synthetic",
        })
    }

    /// One line for people.
    pub fn summary(&self, bench: &PolicyBench) -> String {
        let memory = match (self.traffic, self.floors) {
            (Some(t), Some(f)) => format!(
                "{} bytes/step (mean; first {}, last {}), read bandwidth {:.2} GB/s, \
                 floor {:.1} µs, ratio {:.2}",
                t.bytes_read,
                t.bytes_read_range.0,
                t.bytes_read_range.1,
                f.bandwidth / 1e9,
                f.floor_us,
                f.ratio
            ),
            _ => "memory traffic n/a (not the built-in estimator)".to_string(),
        };
        format!(
            "{} d={} arms={} pretrain/arm={} ({}): median decide+observe {:.1} µs \
             (p10 {:.1}, p90 {:.1}); {memory}; pretraining {:.2} s; load {}; synthetic data",
            self.policy,
            bench.dim,
            bench.arms,
            bench.pretrain,
            self.traffic
                .map_or("representation n/a", |t| t.representation),
            self.per_step_us,
            self.p10_step_us,
            self.p90_step_us,
            self.pretrain_s,
            self.load_average_1m
        )
    }
}

impl Traffic {
    /// The traffic of the timed steps: `arms` (a twin of the policy's
    /// estimator before the first step) is given the policy's observations
    /// in order, and each step after the first `warmup` is counted at the
    /// state it ran on. Replayed after the clock stops, so the twin's own
    /// work never disturbs the timing.
    fn over(
        mut arms: LinearArms,
        observed: &[(Context, ArmId, f64)],
        warmup: usize,
    ) -> Result<Self> {
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
        let (mut read, mut written) = (Vec::new(), Vec::new());
        for (s, (x, arm, reward)) in observed.iter().enumerate() {
            if s >= warmup {
                let update = arms.bytes_per_update(*arm)?;
                read.push(arms.bytes_per_score() + update);
                // A dense update rewrites the factor it read; a kernel
                // update appends O(n).
                written.push(match arms.representation(*arm)? {
                    Representation::Dense => update,
                    Representation::Kernel => 0,
                });
            }
            arms.update(x, *arm, *reward)?;
        }
        let mean = |v: &[usize]| (v.iter().sum::<usize>() as f64 / v.len().max(1) as f64).round();
        Ok(Self {
            representation,
            bytes_read: mean(&read) as usize,
            bytes_read_range: (
                read.first().copied().unwrap_or(0),
                read.last().copied().unwrap_or(0),
            ),
            bytes_written: mean(&written) as usize,
        })
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn small(policy: &str) -> PolicyBench {
        PolicyBench {
            spec: PolicySpec {
                policy: Some(policy.into()),
                ..Default::default()
            },
            dim: 16,
            arms: 3,
            pretrain: 4,
            steps: 25,
            seed: 1,
            probe_bytes: 1 << 16,
            ..Default::default()
        }
    }

    /// Every size outside its limit is refused, naming its flag.
    #[test]
    fn sizes_outside_their_limits_name_the_flag() {
        type Set = fn(&mut PolicyBench);
        let cases: [(&str, Set); 8] = [
            ("--dim", |b| b.dim = 0),
            ("--steps", |b| b.steps = 0),
            ("--dim", |b| b.dim = usize::MAX),
            ("--arms", |b| b.arms = usize::MAX),
            ("--steps", |b| b.steps = usize::MAX),
            ("--pretrain", |b| b.pretrain = usize::MAX),
            ("--pretrain", |b| {
                (b.pretrain, b.arms, b.dim) = (1_000_000, 256, 1024);
            }),
            ("--dim", |b| (b.arms, b.dim) = (1024, 8192)),
        ];
        for (flag, set) in cases {
            let mut b = small("linucb");
            set(&mut b);
            let err = b.run().unwrap_err();
            assert!(
                matches!(err, HilError::InvalidParameter { ref name, .. } if name == flag),
                "{flag}: {err}"
            );
        }
    }

    #[test]
    fn a_builtin_policy_is_timed_against_its_floor() {
        let b = small("linucb_qg");
        let r = b.run().unwrap();
        assert_eq!(r.policy, "linucb_qg");
        let t = r.traffic.expect("the built-in estimator's traffic");
        // 12 fresh pretraining rows of 16 numbers, plus the factors.
        assert!(t.bytes_read >= 12 * 16 * 8, "{t:?}");
        let f = r.floors.expect("a floor");
        assert!(f.floor_us > 0.0 && f.ratio > 0.0);
        assert_eq!(r.bandwidth_samples, 3);
        let j = r.to_json(&b);
        assert_eq!(j["dim"], 16);
        assert_eq!(j["representation"], "kernel");
        assert_eq!(j["data"], "synthetic");
        assert!(r.summary(&b).contains("ratio"));
    }

    #[test]
    fn the_floor_counts_what_each_step_reads_as_the_estimator_grows() {
        let mut b = small("linucb_qg");
        b.spec.representation = Some("kernel".into());
        let t = b.run().unwrap().traffic.unwrap();
        let (first, last) = t.bytes_read_range;
        // Every step stores its fresh context (16 numbers) and adds one
        // observation to a factor: the last timed step reads at least the
        // 24 rows added since the first.
        assert!(last >= first + 24 * 16 * 8, "{t:?}");
        assert!(first < t.bytes_read && t.bytes_read < last, "{t:?}");
    }

    #[test]
    fn shared_contexts_are_stored_once() {
        let fresh = small("linucb").run().unwrap().traffic.unwrap();
        let mut b = small("linucb");
        b.shared_contexts = true;
        let shared = b.run().unwrap().traffic.unwrap();
        assert!(shared.bytes_read < fresh.bytes_read, "{shared:?} {fresh:?}");
    }
}
