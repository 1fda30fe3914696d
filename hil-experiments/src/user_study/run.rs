//! Running the study: the plate schedule, the built methods, the results.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use hil_config::{BuildContext, TaskContext};
use hil_core::session::splitmix;
use hil_core::{
    Environment, EpisodeReport, Policy, Result, Session, SessionObserver, WorkloadModel,
};
use hil_stats::{Stat, mean};
use serde::{Deserialize, Serialize};

use super::config::UserStudyConfig;

/// The method order of repetition `rep` (0-based) over `n` methods, as
/// indices into the study's methods. Even repetitions rotate the first
/// order by `rep / 2`; odd ones reverse the repetition before them. Every
/// pair of repetitions therefore gives every method the same mean
/// position, and `2n` repetitions put every method in every position
/// exactly twice, so learning or fatigue across plates does not favour a
/// method. For three methods the orders are ABC, CBA, BCA, ACB, CAB, BAC.
///
/// ```
/// use hil_experiments::user_study::method_order;
/// assert_eq!(method_order(0, 3), [0, 1, 2]);
/// assert_eq!(method_order(1, 3), [2, 1, 0]);
/// ```
pub fn method_order(rep: usize, n: usize) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let shift = (rep / 2) % n;
    let mut order: Vec<usize> = (0..n).map(|i| (i + shift) % n).collect();
    if rep % 2 == 1 {
        order.reverse();
    }
    order
}

/// One plate of the study: which method the participant meets, when.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Plate {
    /// Index of the method in the config's `methods`.
    pub method: usize,
    /// The method's label.
    pub label: String,
    /// Repetition, 1-based.
    pub repetition: usize,
    /// Position of the plate within its repetition, 1-based.
    pub position: usize,
    /// The plate's episode seed.
    pub seed: u64,
}

/// The result of one plate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlateResult {
    /// The method's label.
    pub method: String,
    /// Repetition, 1-based.
    pub repetition: usize,
    /// Position within the repetition, 1-based.
    pub position: usize,
    /// Mean expected task reward per step.
    pub r_task_avg: f64,
    /// Items fed successfully.
    pub n_success: usize,
    /// Queries asked.
    pub n_q: usize,
    /// Queries asked per food (item label): where the method asks.
    #[serde(default)]
    pub n_q_by_food: BTreeMap<String, usize>,
    /// Queries asked per attempt index at an item (0-based: index 0 counts
    /// queries at first attempts): when the method asks.
    #[serde(default)]
    pub n_q_by_attempt: Vec<usize>,
    /// Steps (attempts) taken.
    pub n_steps: usize,
    /// Change of workload over the plate, ΔWL.
    pub delta_wl: f64,
}

/// How a tuned method's hyperparameter was chosen on validation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// The method's label.
    pub method: String,
    /// The tuned hyperparameter.
    pub parameter: String,
    /// The grid of values tried.
    pub grid: Vec<f64>,
    /// Mean M_wt(`w_task`) over the validation plates, per grid value,
    /// with its standard error (written as `{mean, sem}`).
    #[serde(with = "hil_stats::summary::as_mean_sem::seq")]
    pub m_wt: Vec<Stat>,
    /// Mean queries per validation plate, per grid value.
    pub n_q: Vec<f64>,
    /// The task weight of the criterion.
    pub w_task: f64,
    /// Validation plates per value.
    pub plates: usize,
    /// The value used in the study (highest mean M_wt; ties: the first).
    pub chosen: f64,
}

/// Seed stream of validation plates (apart from the study's plates).
const VALIDATION_STREAM: u64 = 0x7661_6c69_6461_7465;

/// One method's figures, mean ± standard error over its plates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodSummary {
    /// The method's label.
    pub method: String,
    /// Plates the figures are over.
    pub plates: usize,
    /// Mean r_task_avg per plate.
    pub r_task_avg: f64,
    /// Its standard error.
    pub r_task_avg_sem: Option<f64>,
    /// Mean items fed per plate.
    pub n_success_per_plate: f64,
    /// Its standard error.
    pub n_success_per_plate_sem: Option<f64>,
    /// Mean queries per plate.
    pub n_q_per_plate: f64,
    /// Its standard error.
    pub n_q_per_plate_sem: Option<f64>,
    /// Mean queries per plate at each food's items (every food met in
    /// any of the method's plates; 0 on a plate that asked none there).
    #[serde(default)]
    pub n_q_by_food: BTreeMap<String, f64>,
    /// Mean queries per plate at each attempt index (0-based).
    #[serde(default)]
    pub n_q_by_attempt: Vec<f64>,
}

impl MethodSummary {
    fn over(method: &str, plates: &[&PlateResult]) -> Self {
        let col =
            |f: fn(&PlateResult) -> f64| Stat::of(&plates.iter().map(|p| f(p)).collect::<Vec<_>>());
        let r = col(|p| p.r_task_avg);
        let s = col(|p| p.n_success as f64);
        let q = col(|p| p.n_q as f64);
        let n = plates.len().max(1) as f64;
        let mut n_q_by_food = BTreeMap::new();
        for p in plates {
            for (food, &k) in &p.n_q_by_food {
                *n_q_by_food.entry(food.clone()).or_insert(0.0) += k as f64 / n;
            }
        }
        let depth = plates
            .iter()
            .map(|p| p.n_q_by_attempt.len())
            .max()
            .unwrap_or(0);
        let n_q_by_attempt = (0..depth)
            .map(|i| {
                mean(
                    &plates
                        .iter()
                        .map(|p| p.n_q_by_attempt.get(i).copied().unwrap_or(0) as f64)
                        .collect::<Vec<_>>(),
                )
            })
            .collect();
        Self {
            method: method.to_string(),
            plates: plates.len(),
            r_task_avg: r.mean,
            r_task_avg_sem: r.sem(),
            n_success_per_plate: s.mean,
            n_success_per_plate_sem: s.sem(),
            n_q_per_plate: q.mean,
            n_q_per_plate_sem: q.sem(),
            n_q_by_food,
            n_q_by_attempt,
        }
    }
}

/// The protocol a result was produced under.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Protocol {
    /// The environment's name.
    pub environment: String,
    /// The item labels met, in order of first appearance.
    pub foods: Vec<String>,
    /// The methods, in the order of the first repetition.
    pub methods: Vec<String>,
    /// Attempts per item.
    pub n_att: u32,
    /// Initial workload.
    pub wl0: f64,
    /// Repetitions of every method.
    pub repetitions: usize,
    /// Master seed.
    pub seed: u64,
}

/// Everything a study run produced, plain and serialisable.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UserStudyResult {
    /// How it was run.
    pub protocol: Protocol,
    /// Every plate, in the order run.
    pub plates: Vec<PlateResult>,
    /// Per method, in the config's order.
    pub methods: Vec<MethodSummary>,
    /// How each tuned method's hyperparameter was chosen.
    pub selections: Vec<Selection>,
}

/// Runs one plate's episode on the environment it is given, with extra
/// observers; the callback of [`UserStudy::run_with`] calls it, possibly
/// around a wrapper of the environment.
pub type Episode<'a> =
    dyn FnMut(&mut dyn Environment, &mut [&mut dyn SessionObserver]) -> Result<EpisodeReport> + 'a;

/// Runs one plate (of the study or of a validation run) with `policy` and a
/// fresh channel, through `each`; returns its report and the name of the
/// environment it ran on (none if `each` did not run the episode).
fn run_plate<E: ?Sized>(
    cfg: &UserStudyConfig,
    ctx: &TaskContext,
    workload: &Arc<dyn WorkloadModel>,
    policy: &mut dyn Policy,
    plate: &Plate,
    env: &mut E,
    each: &mut impl FnMut(&Plate, &mut E, &mut Episode<'_>) -> Result<EpisodeReport>,
) -> Result<(EpisodeReport, Option<String>)> {
    let mut channel = cfg.channel.build(ctx)?;
    let mut env_name = None;
    let mut episode = |env: &mut dyn Environment, observers: &mut [&mut dyn SessionObserver]| {
        env_name = Some(env.name().to_string());
        Session::new(
            cfg.session.clone(),
            env,
            &mut *policy,
            channel.as_mut(),
            Arc::clone(workload),
        )
        .run_episode(plate.seed, observers)
    };
    let report = each(plate, env, &mut episode)?;
    Ok((report, env_name))
}

/// A built study: every method's policy and the workload model, ready to
/// run plates on an environment built from the same config.
pub struct UserStudy<'c> {
    config: &'c UserStudyConfig,
    /// The master seed (the config's, or another for a run over seeds).
    seed: u64,
    ctx: TaskContext,
    policies: Vec<Box<dyn Policy>>,
    workload: Arc<dyn WorkloadModel>,
}

impl std::fmt::Debug for UserStudy<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UserStudy")
            .field("methods", &self.config.labels())
            .field("workload", &self.workload.name())
            .field("seed", &self.seed)
            .finish()
    }
}

impl UserStudyConfig {
    /// Builds the methods' policies and the workload model for `environment`
    /// (built from this config's `[environment]`, e.g. by
    /// [`UserStudyConfig::build_environment`]): the policies see its action
    /// space, context dimension and the pretraining data `[environment]`
    /// offers, as in an experiment file.
    pub fn prepare(&self, base_dir: &Path, environment: &dyn Environment) -> Result<UserStudy<'_>> {
        self.prepare_on_seed(base_dir, environment, self.seed)
    }

    /// [`UserStudyConfig::prepare`] under master seed `seed` instead of the
    /// config's.
    fn prepare_on_seed(
        &self,
        base_dir: &Path,
        environment: &dyn Environment,
        seed: u64,
    ) -> Result<UserStudy<'_>> {
        self.validate()?;
        let base = BuildContext::new(base_dir, seed);
        let ctx = base.describe_environment(self.environment.as_ref(), environment)?;
        let workload = self.workload.build(&base)?;
        let policies = self
            .methods
            .iter()
            .map(|m| {
                m.config(&None)?.build(&ctx).map_err(|e| {
                    hil_core::HilError::invalid_input(
                        format!("method `{}`", m.label),
                        e.to_string(),
                    )
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(UserStudy {
            config: self,
            seed,
            ctx,
            policies,
            workload,
        })
    }

    /// Builds the environment once, then runs every plate on it, calling
    /// `on_plate` after each.
    ///
    /// ```
    /// use hil_experiments::user_study::UserStudyConfig;
    /// // A cheap environment: the bundled synthetic food dataset.
    /// let cfg = UserStudyConfig::parse(
    ///     r#"
    ///     repetitions = 1
    ///     [environment]
    ///     type = "food_replay"
    ///     foods = ["banana", "carrot"]
    ///     pretrain_foods = ["apple", "kiwi"]
    ///     items_per_episode = 3
    ///     "#,
    ///     "study.toml".as_ref(),
    /// )
    /// .unwrap();
    /// let result = cfg.run(".".as_ref(), |_| {}).unwrap();
    /// assert_eq!(result.plates.len(), 3);
    /// assert_eq!(result.methods[2].method, "LinUCB-QG");
    /// ```
    pub fn run(
        &self,
        base_dir: &Path,
        on_plate: impl FnMut(&PlateResult),
    ) -> Result<UserStudyResult> {
        self.run_on_seed(base_dir, self.seed, on_plate)
    }

    /// [`UserStudyConfig::run`] under master seed `seed` instead of the
    /// config's: the result is the one a copy of the config with `seed =
    /// seed` gives.
    pub fn run_on_seed(
        &self,
        base_dir: &Path,
        seed: u64,
        mut on_plate: impl FnMut(&PlateResult),
    ) -> Result<UserStudyResult> {
        let mut env = self.environment.build(&BuildContext::new(base_dir, seed))?;
        let mut study = self.prepare_on_seed(base_dir, env.as_ref(), seed)?;
        study.run_with(
            env.as_mut(),
            |_, env, episode| episode(env, &mut []),
            |p| on_plate(p),
        )
    }
}

impl UserStudy<'_> {
    /// Every plate in the order it is run: repetitions one after another,
    /// the methods of each in [`method_order`].
    pub fn schedule(&self) -> Vec<Plate> {
        let n = self.config.methods.len();
        (0..self.config.repetitions)
            .flat_map(|rep| {
                method_order(rep, n)
                    .into_iter()
                    .enumerate()
                    .map(move |(position, method)| (rep, position, method))
            })
            .map(|(rep, position, method)| Plate {
                method,
                label: self.config.methods[method].label.clone(),
                repetition: rep + 1,
                position: position + 1,
                seed: splitmix(self.seed, (rep * n + position) as u64),
            })
            .collect()
    }

    /// Runs every plate on `env`. For each plate, `each` receives the plate,
    /// the environment and the [`Episode`] to run on it: call it on `env`
    /// itself, or on a wrapper (e.g. one that records keyframes), with any
    /// observers. `on_plate` sees each result as it comes. A policy keeps
    /// what it learnt on one plate for its next; a fresh channel answers
    /// every plate.
    pub fn run_with<E: ?Sized>(
        &mut self,
        env: &mut E,
        mut each: impl FnMut(&Plate, &mut E, &mut Episode<'_>) -> Result<EpisodeReport>,
        mut on_plate: impl FnMut(&PlateResult),
    ) -> Result<UserStudyResult> {
        let cfg = self.config;
        let selections = self.select_tuned(env, &mut each)?;
        let mut plates = Vec::new();
        let mut foods: Vec<String> = Vec::new();
        let mut env_name = String::new();
        for plate in self.schedule() {
            let policy = self.policies[plate.method].as_mut();
            let (report, name) = run_plate(
                cfg,
                &self.ctx,
                &self.workload,
                policy,
                &plate,
                env,
                &mut each,
            )?;
            if let Some(name) = name {
                env_name = name;
            }
            let mut n_q_by_food = BTreeMap::new();
            let mut n_q_by_attempt = vec![0usize; cfg.session.n_att as usize];
            for e in &report.events {
                if !foods.contains(&e.step.item_label) {
                    foods.push(e.step.item_label.clone());
                }
                // Every food on the plate appears, asked at or not.
                let at_food = n_q_by_food.entry(e.step.item_label.clone()).or_insert(0);
                if e.step.decision.is_query() {
                    *at_food += 1;
                    let i = e.step.attempt as usize;
                    if i >= n_q_by_attempt.len() {
                        n_q_by_attempt.resize(i + 1, 0);
                    }
                    n_q_by_attempt[i] += 1;
                }
            }
            let m = &report.metrics;
            let result = PlateResult {
                method: plate.label.clone(),
                repetition: plate.repetition,
                position: plate.position,
                r_task_avg: m.r_task_avg,
                n_success: m.n_success,
                n_q: m.n_q,
                n_q_by_food,
                n_q_by_attempt,
                n_steps: m.n_steps,
                delta_wl: m.delta_wl,
            };
            on_plate(&result);
            plates.push(result);
        }
        let methods = cfg
            .labels()
            .into_iter()
            .map(|label| {
                let mine: Vec<&PlateResult> = plates.iter().filter(|p| p.method == label).collect();
                MethodSummary::over(label, &mine)
            })
            .collect();
        Ok(UserStudyResult {
            protocol: Protocol {
                environment: env_name,
                foods,
                methods: cfg.labels().into_iter().map(String::from).collect(),
                n_att: cfg.session.n_att,
                wl0: cfg.session.wl0,
                repetitions: cfg.repetitions,
                seed: self.seed,
            },
            plates,
            methods,
            selections,
        })
    }

    /// The validation phase: for every tuned method, runs
    /// `validation.plates` plates at every grid value with a fresh policy,
    /// keeps the value with the highest mean M_wt and rebuilds the
    /// method's policy at it. Validation plates reach `each` with
    /// repetition 0.
    fn select_tuned<E: ?Sized>(
        &mut self,
        env: &mut E,
        each: &mut impl FnMut(&Plate, &mut E, &mut Episode<'_>) -> Result<EpisodeReport>,
    ) -> Result<Vec<Selection>> {
        let cfg = self.config;
        let v = &cfg.validation;
        let mut selections = Vec::new();
        for (k, method) in cfg.methods.iter().enumerate() {
            let Some((parameter, grid)) = method.tune.iter().next() else {
                continue;
            };
            let mut m_wt = Vec::new();
            let mut n_q = Vec::new();
            for point in method.grid() {
                let mut policy = method.config(&point)?.build(&self.ctx)?;
                let value = point.as_ref().map_or(f64::NAN, |p| p.1);
                let mut scores = Vec::new();
                let mut queries = 0usize;
                for i in 0..v.plates {
                    let plate = Plate {
                        method: k,
                        label: format!("{} (validation, {parameter} = {value})", method.label),
                        repetition: 0,
                        position: i + 1,
                        seed: splitmix(self.seed ^ VALIDATION_STREAM, i as u64),
                    };
                    let (report, _) = run_plate(
                        cfg,
                        &self.ctx,
                        &self.workload,
                        policy.as_mut(),
                        &plate,
                        env,
                        each,
                    )?;
                    scores.push(report.metrics.m_wt(v.w_task));
                    queries += report.metrics.n_q;
                }
                m_wt.push(Stat::of(&scores));
                n_q.push(queries as f64 / v.plates as f64);
            }
            let best =
                (0..grid.len()).fold(0, |b, i| if m_wt[i].mean > m_wt[b].mean { i } else { b });
            let chosen = grid[best];
            self.policies[k] = method
                .config(&Some((parameter.clone(), chosen)))?
                .build(&self.ctx)?;
            selections.push(Selection {
                method: method.label.clone(),
                parameter: parameter.clone(),
                grid: grid.clone(),
                m_wt,
                n_q,
                w_task: v.w_task,
                plates: v.plates,
                chosen,
            });
        }
        Ok(selections)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_order_is_counterbalanced() {
        for n in 1..=6 {
            // Every pair of repetitions: equal mean position for every method.
            let mut sum = vec![0; n];
            for rep in 0..2 {
                for (p, &m) in method_order(rep, n).iter().enumerate() {
                    sum[m] += p;
                }
            }
            assert!(sum.iter().all(|&s| s == n - 1), "n = {n}: {sum:?}");
            // 2n repetitions: every method twice in every position.
            let mut pos = vec![vec![0; n]; n];
            for rep in 0..2 * n {
                let o = method_order(rep, n);
                let mut seen = o.clone();
                seen.sort();
                assert_eq!(seen, (0..n).collect::<Vec<_>>());
                for (p, &m) in o.iter().enumerate() {
                    pos[m][p] += 1;
                }
            }
            assert!(pos.iter().flatten().all(|&c| c == 2), "n = {n}: {pos:?}");
        }
        // The paper's three methods: the six orders, in the order used so far.
        let orders: Vec<Vec<usize>> = (0..6).map(|r| method_order(r, 3)).collect();
        assert_eq!(
            orders,
            [
                [0, 1, 2],
                [2, 1, 0],
                [1, 2, 0],
                [0, 2, 1],
                [2, 0, 1],
                [1, 0, 2]
            ]
        );
    }
}
