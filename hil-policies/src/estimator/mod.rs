//! The shared linear-arm estimator: per-arm ridge regression with UCB bonus.
//!
//! For each arm a: A_a = λI + X_aᵀX_a, b_a = X_aᵀr_a, θ_a = A_a⁻¹b_a and the
//! bonus b_a(x) = sqrt(xᵀA_a⁻¹x). Each arm is held in the cheaper of two
//! exact representations ([`Representation`]): the kernel (Woodbury) form
//! while it has few observations compared with d, a packed dense Cholesky
//! factor beyond. Both agree with a direct inverse (the crate's test-only
//! `reference` estimator) to rounding.

mod checkpoint;
mod dense;
mod kernel;
mod linalg;
mod options;
#[cfg(test)]
mod reference;
mod store;
#[cfg(test)]
mod tests;

use std::sync::Arc;

use faer::Mat;
use hil_core::{ArmId, Context, HilError, LabelledObservation, Result};

use dense::DenseArm;
use kernel::KernelArm;
pub use options::{DEFAULT_CROSSOVER, EstimatorOptions, Representation, RepresentationChoice};
use store::RowStore;

/// The estimate and the confidence width of one arm at one context.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmEstimate {
    /// θᵀx.
    pub estimate: f64,
    /// sqrt(xᵀA⁻¹x), before scaling by α.
    pub bonus: f64,
}

impl ArmEstimate {
    /// The upper confidence bound θᵀx + α·b(x).
    pub fn ucb(&self, alpha: f64) -> f64 {
        self.estimate + alpha * self.bonus
    }

    /// The lower confidence bound θᵀx − α·b(x).
    pub fn lcb(&self, alpha: f64) -> f64 {
        self.estimate - alpha * self.bonus
    }
}

#[derive(Clone, Debug)]
enum Arm {
    Kernel(KernelArm),
    Dense(DenseArm),
}

impl Arm {
    fn n(&self) -> usize {
        match self {
            Arm::Kernel(k) => k.n(),
            Arm::Dense(d) => d.n(),
        }
    }
}

/// One operation in the estimator's history (replayed to restore a checkpoint
/// bit for bit).
#[derive(Clone, Debug)]
enum Op {
    Pretrain(Arc<[LabelledObservation]>),
    Update(LabelledObservation),
}

/// Scratch state of the last [`LinearArms::scores`] call, reused by the
/// following [`LinearArms::update`] at the same context.
#[derive(Clone, Debug, Default)]
struct ScoreCache {
    version: u64,
    valid: bool,
    x: Vec<f64>,
    xx: f64,
    /// z = L⁻¹Xx per kernel arm.
    z: Vec<Vec<f64>>,
    g: Vec<f64>,
    w: Vec<f64>,
}

/// Per-arm ridge regressions sharing one context dimension and one λ.
///
/// Cheap to reason about and exact: pretrain once, then clone the estimator
/// for every run of a protocol.
///
/// ```
/// use hil_core::{ArmId, Context, LabelledObservation};
/// use hil_policies::LinearArms;
///
/// let mut arms = LinearArms::new(2, 3, 1.0).unwrap();
/// let x = Context::new(vec![1.0, 0.0, 0.5]).unwrap();
/// arms.pretrain(&[LabelledObservation { context: x.clone(), arm: ArmId(0), reward: 1.0 }])
///     .unwrap();
/// arms.update(&x, ArmId(1), 0.0).unwrap();
/// let s = arms.scores(&x).unwrap();
/// // Arm 0 saw reward 1 at x: θᵀx = |x|²/(λ + |x|²) = 1.25/2.25.
/// assert!((s[0].estimate - 1.25 / 2.25).abs() < 1e-12);
/// assert!(s[1].estimate.abs() < 1e-12);
/// assert!(arms.scores(&[f64::NAN, 0.0, 0.0]).is_err());
/// ```
#[derive(Clone, Debug)]
pub struct LinearArms {
    n_arms: usize,
    dim: usize,
    lambda: f64,
    options: EstimatorOptions,
    arms: Vec<Arm>,
    store: RowStore,
    history: Vec<Op>,
    version: u64,
    cache: ScoreCache,
}

impl LinearArms {
    /// An estimator for `n_arms` arms over `dim`-dimensional contexts with
    /// ridge strength `lambda`, choosing representations by cost.
    pub fn new(n_arms: usize, dim: usize, lambda: f64) -> Result<Self> {
        Self::with_options(n_arms, dim, lambda, EstimatorOptions::default())
    }

    /// Like [`LinearArms::new`] with explicit representation options.
    pub fn with_options(
        n_arms: usize,
        dim: usize,
        lambda: f64,
        options: EstimatorOptions,
    ) -> Result<Self> {
        // Checked before anything is allocated: a dense arm holds a d × d
        // factor, so a 20-digit `dim` must be an error, not an abort.
        use hil_config::limits::{ARMS, CONTEXT_DIM, check_count};
        check_count("n_arms", n_arms, ARMS)?;
        check_count("dim", dim, CONTEXT_DIM)?;
        check_lambda(lambda)?;
        options.validate()?;
        let mut me = Self {
            n_arms,
            dim,
            lambda,
            options,
            arms: Vec::with_capacity(n_arms),
            store: RowStore::new(dim),
            history: Vec::new(),
            version: 0,
            cache: ScoreCache::default(),
        };
        for _ in 0..n_arms {
            let arm = me.build_arm(&[], &[])?;
            me.arms.push(arm);
        }
        Ok(me)
    }

    /// Number of arms.
    pub fn n_arms(&self) -> usize {
        self.n_arms
    }

    /// Context dimension d.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Ridge strength λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The representation options.
    pub fn options(&self) -> EstimatorOptions {
        self.options
    }

    /// The representation `arm` is currently held in.
    pub fn representation(&self, arm: ArmId) -> Result<Representation> {
        self.check_arm(arm)?;
        Ok(match &self.arms[arm.0] {
            Arm::Kernel(_) => Representation::Kernel,
            Arm::Dense(_) => Representation::Dense,
        })
    }

    /// Number of observations of `arm` (pretraining and online).
    pub fn n_observations(&self, arm: ArmId) -> Result<usize> {
        self.check_arm(arm)?;
        Ok(self.arms[arm.0].n())
    }

    /// Bytes of estimator state one [`LinearArms::scores`] call streams:
    /// the shared context rows (if any arm is in kernel form) plus every
    /// arm's factor.
    pub fn bytes_per_score(&self) -> usize {
        let mut bytes = 0;
        let mut any_kernel = false;
        for a in &self.arms {
            bytes += match a {
                Arm::Kernel(k) => {
                    any_kernel = true;
                    k.factor_bytes()
                }
                Arm::Dense(d) => d.factor_bytes(),
            };
        }
        if any_kernel {
            bytes += self.store.bytes();
        }
        bytes
    }

    /// Bytes of estimator state one [`LinearArms::update`] of `arm` reads
    /// (and, for the dense form, writes back).
    pub fn bytes_per_update(&self, arm: ArmId) -> Result<usize> {
        self.check_arm(arm)?;
        Ok(match &self.arms[arm.0] {
            // Reuses the scoring pass; touches O(n) numbers.
            Arm::Kernel(k) => k.n() * 3 * std::mem::size_of::<f64>(),
            Arm::Dense(d) => d.factor_bytes(),
        })
    }

    /// Adds a batch of observations (e.g. a pretraining dataset). Every
    /// record is validated before anything changes; each arm touched is
    /// rebuilt from all its observations in one factorisation.
    pub fn pretrain(&mut self, data: &[LabelledObservation]) -> Result<()> {
        for (i, obs) in data.iter().enumerate() {
            self.check_observation(&obs.context, obs.arm, obs.reward)
                .map_err(|e| {
                    HilError::invalid_input(format!("pretraining record #{i}"), e.to_string())
                })?;
        }
        if data.is_empty() {
            return Ok(());
        }
        self.apply_pretrain(data.into())
    }

    /// Adds one observation: `arm` was executed at `x` with `reward`.
    pub fn update(&mut self, x: &Context, arm: ArmId, reward: f64) -> Result<()> {
        self.check_observation(x, arm, reward)?;
        self.apply_update(LabelledObservation {
            context: x.clone(),
            arm,
            reward,
        })
    }

    /// Estimates and bonuses of every arm at `x`.
    ///
    /// One pass over the estimator state; the intermediate solves are kept
    /// so that an [`LinearArms::update`] at the same `x` right after costs
    /// O(n) for an arm in kernel form.
    pub fn scores(&mut self, x: &[f64]) -> Result<Vec<ArmEstimate>> {
        self.check_x(x)?;
        let cache = &mut self.cache;
        cache.x.clear();
        cache.x.extend_from_slice(x);
        cache.xx = linalg::dot(x, x);
        cache.version = self.version;
        cache.z.resize_with(self.n_arms, Vec::new);
        if self.arms.iter().any(|a| matches!(a, Arm::Kernel(_))) {
            self.store.products(x, &mut cache.g);
        }
        let mut out = Vec::with_capacity(self.n_arms);
        for (a, arm) in self.arms.iter().enumerate() {
            let (est, q) = match arm {
                Arm::Kernel(k) => {
                    k.score_from_products(&cache.g, cache.xx, self.lambda, &mut cache.z[a])
                }
                Arm::Dense(d) => d.score(x, &mut cache.w),
            };
            out.push(ArmEstimate {
                estimate: est,
                bonus: q.sqrt(),
            });
        }
        cache.valid = true;
        Ok(out)
    }

    /// θ_aᵀx and sqrt(xᵀA_a⁻¹x) for one arm (no caching).
    pub fn estimate(&self, arm: ArmId, x: &[f64]) -> Result<ArmEstimate> {
        self.check_arm(arm)?;
        self.check_x(x)?;
        let mut z = Vec::new();
        let (est, q) = match &self.arms[arm.0] {
            Arm::Kernel(k) => k.score_direct(&self.store, x, self.lambda, &mut z),
            Arm::Dense(d) => d.score(x, &mut z),
        };
        Ok(ArmEstimate {
            estimate: est,
            bonus: q.sqrt(),
        })
    }

    /// The bonus sqrt(xᵀA_a⁻¹x) of one arm.
    pub fn bonus(&self, arm: ArmId, x: &[f64]) -> Result<f64> {
        Ok(self.estimate(arm, x)?.bonus)
    }

    /// θ_a = A_a⁻¹b_a, explicitly (O(n·d) or O(d²); for inspection and tests).
    pub fn theta(&self, arm: ArmId) -> Result<Vec<f64>> {
        self.check_arm(arm)?;
        Ok(match &self.arms[arm.0] {
            Arm::Kernel(k) => k.theta(&self.store, self.dim),
            Arm::Dense(d) => d.theta(),
        })
    }

    fn check_arm(&self, arm: ArmId) -> Result<()> {
        if arm.0 < self.n_arms {
            Ok(())
        } else {
            Err(HilError::ArmOutOfRange {
                arm: arm.0,
                n_arms: self.n_arms,
            })
        }
    }

    fn check_x(&self, x: &[f64]) -> Result<()> {
        if x.len() != self.dim {
            return Err(HilError::DimensionMismatch {
                expected: self.dim,
                got: x.len(),
            });
        }
        hil_core::context::check_finite("context", x)
    }

    fn check_observation(&self, x: &Context, arm: ArmId, reward: f64) -> Result<()> {
        self.check_x(x)?;
        self.check_arm(arm)?;
        if !reward.is_finite() {
            return Err(HilError::invalid_input(
                "reward",
                format!("{reward} is not finite"),
            ));
        }
        Ok(())
    }

    fn apply_pretrain(&mut self, data: Arc<[LabelledObservation]>) -> Result<()> {
        let mut touched = vec![false; self.n_arms];
        for obs in data.iter() {
            touched[obs.arm.0] = true;
        }
        self.history.push(Op::Pretrain(data));
        for (a, t) in touched.iter().enumerate() {
            if *t {
                let (xs, rs) = self.arm_history(ArmId(a));
                self.arms[a] = self.build_arm(&xs, &rs)?;
            }
        }
        self.after_change();
        // Pretraining rows are shared by every clone of this estimator.
        self.store.freeze();
        Ok(())
    }

    fn apply_update(&mut self, obs: LabelledObservation) -> Result<()> {
        let a = obs.arm.0;
        let n_after = self.arms[a].n() + 1;
        let target = self.options.target(n_after, self.dim);
        let x: &[f64] = &obs.context;
        match (&mut self.arms[a], target) {
            (Arm::Kernel(k), Representation::Kernel) => {
                let c = &mut self.cache;
                let cached = c.valid
                    && c.version == self.version
                    && c.z.get(a).is_some_and(|z| z.len() == k.n())
                    && c.x.iter().zip(x).all(|(p, q)| p.to_bits() == q.to_bits());
                let (z, xx) = if cached {
                    (std::mem::take(&mut c.z[a]), c.xx)
                } else {
                    let mut z = Vec::new();
                    k.score_direct(&self.store, x, self.lambda, &mut z);
                    (z, linalg::dot(x, x))
                };
                let row = self.store.insert(x);
                k.push(row, &z, xx, obs.reward, self.lambda);
                self.history.push(Op::Update(obs));
            }
            (Arm::Dense(d), _) => {
                d.update(x, obs.reward);
                self.history.push(Op::Update(obs));
            }
            (Arm::Kernel(_), Representation::Dense) => {
                // Crossing over: refactorise densely from all observations.
                let arm = obs.arm;
                self.history.push(Op::Update(obs));
                let (xs, rs) = self.arm_history(arm);
                self.arms[a] = self.build_arm(&xs, &rs)?;
            }
        }
        self.after_change();
        Ok(())
    }

    /// Invalidates the score cache and drops store rows no kernel arm uses.
    fn after_change(&mut self) {
        self.version += 1;
        self.cache.valid = false;
        let mut keep = vec![false; self.store.len()];
        for a in &self.arms {
            if let Arm::Kernel(k) = a {
                for &r in &k.rows {
                    keep[r as usize] = true;
                }
            }
        }
        // Compaction is O(rows · d); only worth it when much is dead, which
        // happens only when arms cross over to the dense form.
        let live = keep.iter().filter(|k| **k).count();
        if live * 2 < keep.len() || (live == 0 && !keep.is_empty()) {
            let map = self.store.compact(&keep);
            for a in &mut self.arms {
                if let Arm::Kernel(k) = a {
                    k.remap(&map);
                }
            }
        }
    }

    /// All observations of `arm`, in the order they were added.
    fn arm_history(&self, arm: ArmId) -> (Vec<Context>, Vec<f64>) {
        let mut xs = Vec::new();
        let mut rs = Vec::new();
        let mut take = |o: &LabelledObservation| {
            if o.arm == arm {
                xs.push(o.context.clone());
                rs.push(o.reward);
            }
        };
        for op in &self.history {
            match op {
                Op::Pretrain(batch) => batch.iter().for_each(&mut take),
                Op::Update(o) => take(o),
            }
        }
        (xs, rs)
    }

    /// Factorises an arm from scratch in the representation its size calls for.
    fn build_arm(&mut self, xs: &[Context], rs: &[f64]) -> Result<Arm> {
        Ok(match self.options.target(xs.len(), self.dim) {
            Representation::Kernel => {
                let rows = xs.iter().map(|x| self.store.insert(x)).collect();
                Arm::Kernel(KernelArm::build(
                    rows,
                    rs.to_vec(),
                    &self.store,
                    self.dim,
                    self.lambda,
                )?)
            }
            Representation::Dense => {
                let x = Mat::<f64>::from_fn(xs.len(), self.dim, |i, j| xs[i][j]);
                Arm::Dense(DenseArm::build(&x, rs, self.lambda)?)
            }
        })
    }
}

pub(crate) fn check_lambda(lambda: f64) -> Result<()> {
    if lambda.is_finite() && lambda > 0.0 {
        Ok(())
    } else {
        Err(HilError::invalid_parameter(
            "lambda",
            lambda,
            "the ridge strength must be a finite number > 0 (it keeps A = λI + XᵀX invertible)",
        ))
    }
}
