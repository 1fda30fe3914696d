//! The paper's simulated-testbed protocol.
//!
//! 1. Split the foods (pretrain / validation / test, [`FoodSplit`]). Every
//!    policy is built through its [`PolicyConfig`](hil_config::PolicyConfig) with a [`BuildContext`]
//!    that offers the pretraining foods' (context, arm, reward) data, so a
//!    config with `pretrain = true` starts from the pretrained estimator.
//! 2. Run every (phase, method, grid value, seed[, policy seed][, deciding
//!    workload model]) episode once, in parallel. What a method needs comes
//!    from its config: one that does not read the workload forecast
//!    ([`PolicyConfig::uses_workload_forecast`](hil_config::PolicyConfig::uses_workload_forecast)) runs once and is scored under
//!    every model; one that does runs once per deciding model; a stochastic
//!    one ([`PolicyConfig::is_stochastic`](hil_config::PolicyConfig::is_stochastic)) runs under `n_policy_seeds`
//!    policy seeds. w_task never changes a run, only how it is scored.
//! 3. For every scoring model and w_task, choose each tuned method's
//!    hyperparameter maximising the mean M_wt over the validation runs,
//!    then report the test metrics of that choice.
//! 4. Cross-data: a method deciding with one model and scored with another
//!    ([`EpisodeMetrics::rescored`]), its hyperparameter chosen on
//!    validation with the deciding model (as the paper's numbers show: its
//!    cross-data r_task and f_q equal the same-model rows).
//!
//! What answers queries, what presents the items and the workload models
//! are pluggable ([`crate::components`], [`ModelSource`]): the paper's
//! perfect expert and dataset replay by default, any registered type from
//! the settings, or a factory given in code.
//!
//! Scoring is hil-core's, the paper's: ΔWL = f(WL_0, Q_T) − WL_0 at the
//! episode's final timestep ([`EpisodeMetrics`]); nothing here recomputes it.
//!
//! Methods are ordinary policy configs, built-in or plugin types:
//!
//! ```toml
//! [[methods]]
//! label = "LinUCB-QG"
//! policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, pretrain = true, w = 1.0 }
//! tune = { w = [0.25, 0.5, 1.0, 2.0] }   # at most one tuned hyperparameter
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use hil_config::{BuildContext, TaskContext, WorkloadModelConfig};
use hil_core::session::{ComponentSeeds, splitmix};
use hil_core::{
    EpisodeMetrics, HilError, Result, Session, SessionSettings, StepDecision, Timestep,
    WorkloadModel,
};
use hil_envs::env::{PretrainReward, pretraining_data};
use hil_envs::{FoodDataset, FoodSplit};
use hil_jobs::Runner;
use hil_paper::methods::{ALWAYS_QUERY, LINUCB_EXPDECAY, LINUCB_QG, PaperMethod};
use hil_paper::simulation;

use crate::calibrate::End;
use crate::components::{
    ConfiguredChannel, ConfiguredEnvironment, DatasetReplay, EpisodeSpec, PerfectExpertChannel,
    SharedChannelFactory, SharedEnvironmentFactory, check_matches_task,
};
use crate::grids::{GridVariant, PAPER_IMPLIED, union_points};
use crate::method::{GridPoint, Method};
use crate::results::Reproduction;
use serde::{Deserialize, Serialize};

/// A cross-data setting: a method deciding with one model, scored with another.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrossSetting {
    /// The label of the method (it must read the workload forecast).
    pub method: String,
    /// The model the method decides with.
    pub decide: String,
    /// The model ΔWL and M_wt are computed with.
    pub score: String,
}

/// Which runs the report's figures show.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSettings {
    /// The workload model the figures use (the run's first model if it has
    /// none of this name).
    pub model: String,
    /// The w_task whose chosen hyperparameters the figures use (the first
    /// scored w_task if this one is not scored).
    pub w_task: f64,
    /// The method whose gap and threshold are plotted over one episode.
    pub rollout: String,
    /// The methods whose workload curves are compared.
    pub workload: Vec<String>,
}

fn default_grid_name() -> String {
    "default".into()
}

/// Everything that defines a protocol run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProtocolSettings {
    /// Plugin libraries to load before the methods are parsed (relative to
    /// the settings file), so methods may name plugin policy types.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plugins: Vec<PathBuf>,
    /// The food dataset directory (relative to the settings file); none:
    /// hil-envs' bundled synthetic dataset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dataset: Option<PathBuf>,
    /// The workload models, decision and scoring, in table order.
    pub models: Vec<ModelSource>,
    /// Food split.
    pub split: FoodSplit,
    /// N_att and WL_0.
    pub session: SessionSettings,
    /// Items per episode.
    pub items_per_episode: usize,
    /// Master seed; environment and policy seeds derive from it.
    pub seed: u64,
    /// Number of environment seeds of the paper's protocol (its tables give
    /// mean ± population std over these, as the paper's do).
    pub n_seeds: usize,
    /// Environment seeds of the many-seed run beside it (0: none). Its
    /// tables give mean ± standard error; its first `n_seeds` seeds are the
    /// paper-protocol run's, so both come from one set of episodes.
    #[serde(default)]
    pub many_seeds: usize,
    /// Policy seeds for stochastic methods.
    pub n_policy_seeds: usize,
    /// The w_task values scored.
    pub w_tasks: Vec<f64>,
    /// The methods, in table order.
    pub methods: Vec<Method>,
    /// Cross-data settings.
    #[serde(default)]
    pub cross: Vec<CrossSetting>,
    /// w_task of the cross-data experiment.
    pub cross_w_task: f64,
    /// What the figures show.
    pub figures: FigureSettings,
    /// The name of the methods' own grids in tables (e.g. `paper-implied`).
    #[serde(default = "default_grid_name")]
    pub grid_name: String,
    /// Other grids, selected over the same runs (the protocol runs the
    /// union of every grid once); the claims are checked under each.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub grid_variants: Vec<GridVariant>,
    /// What answers the policies' queries: a query-channel table (`type =
    /// "..."`, any built-in, plugin or Python-registered type, and its
    /// parameters); none: the paper's perfect expert
    /// ([`crate::components`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<toml::Table>,
    /// What presents the food items: an environment table (any registered
    /// type) given the phase's `foods`, `items_per_episode` and `dataset`
    /// by the protocol ([`ConfiguredEnvironment`]); none: the paper's
    /// dataset replay over the phase's foods.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<toml::Table>,
}

impl ProtocolSettings {
    /// The paper's protocol: 3 seeds, 5 policy seeds, N_att = 10,
    /// WL_0 = 0.5, 5 items per episode, w_task ∈ {0.2, …, 0.9}, the four
    /// methods, f1-on-f2 and f12-on-f2 at w_task = 0.4, on the three
    /// calibrated variants of the simulation models (`f*_sim` lean,
    /// `f*_sim_mid` middle, `f*_sim_steep`), with a 30-seed run beside it
    /// for standard errors. ExpDecay's c grid is the one the paper's
    /// published f_q imply, QG's w grid is ours ([`crate::grids`]); hil's
    /// own grids run beside them as a grid variant.
    pub fn paper() -> Self {
        // f1-on-f2 and f12-on-f2 at every calibrated variant.
        let cross = End::ALL
            .into_iter()
            .flat_map(|end| {
                ["f1_sim", "f12_sim"].map(|decide| CrossSetting {
                    method: LINUCB_QG.into(),
                    decide: end.model_name(decide),
                    score: end.model_name("f2_sim"),
                })
            })
            .collect();
        Self {
            plugins: Vec::new(),
            dataset: None,
            models: hil_workload::bundled::CALIBRATED
                .iter()
                .map(|n| ModelSource::bundled(n))
                .collect(),
            split: FoodSplit::paper(),
            session: SessionSettings::default(),
            items_per_episode: 5,
            seed: 0,
            n_seeds: simulation::SEEDS,
            many_seeds: 30,
            n_policy_seeds: simulation::EXPDECAY_POLICY_SEEDS,
            w_tasks: simulation::W_TASKS.to_vec(),
            methods: PaperMethod::ALL.into_iter().map(Method::paper).collect(),
            cross,
            cross_w_task: simulation::CROSS_W_TASK,
            figures: FigureSettings {
                model: "f2_sim".into(),
                w_task: simulation::FIGURE_W_TASK,
                rollout: LINUCB_QG.into(),
                workload: vec![
                    ALWAYS_QUERY.into(),
                    LINUCB_EXPDECAY.into(),
                    LINUCB_QG.into(),
                ],
            },
            grid_name: PAPER_IMPLIED.into(),
            grid_variants: vec![GridVariant::hil()],
            channel: None,
            environment: None,
        }
    }

    /// The paper's protocol with hil's own grids as the headline and the
    /// paper-implied ones as the variant: the same runs as [`Self::paper`]
    /// (`examples/configs/paper-protocol-hil-grids.toml`).
    pub fn paper_with_hil_grids() -> Result<Self> {
        let mut s = Self::paper().with_grids(&GridVariant::hil())?;
        s.grid_variants = vec![GridVariant::paper_implied()];
        Ok(s)
    }

    /// The same settings with variant `v`'s grids as the methods' own and
    /// no other variant: what selection and aggregation under `v` read.
    pub fn with_grids(&self, v: &GridVariant) -> Result<Self> {
        let mut s = self.clone();
        s.methods = v.apply(&self.methods)?;
        s.grid_name.clone_from(&v.name);
        s.grid_variants.clear();
        Ok(s)
    }

    /// The settings under each grid variant, in order ([`Self::with_grids`]).
    pub fn variants(&self) -> Result<Vec<Self>> {
        self.grid_variants
            .iter()
            .map(|v| self.with_grids(v))
            .collect()
    }

    /// Every grid point method `i` is run at: its own grid's and every
    /// variant's, each once.
    pub fn run_points(&self, i: usize) -> Result<Vec<GridPoint>> {
        let variants = self.variants()?;
        let mut grids = vec![&self.methods[i]];
        grids.extend(variants.iter().map(|v| &v.methods[i]));
        Ok(union_points(&grids))
    }

    /// A fast smoke version: 3-point grids, 2 policy seeds, a 5-seed run
    /// beside the 3-seed protocol.
    pub fn quick() -> Self {
        let mut s = Self::paper();
        s.n_policy_seeds = 2;
        s.many_seeds = 5;
        for m in &mut s.methods {
            for (name, values) in m.tune.iter_mut() {
                *values = match name.as_str() {
                    "c" => vec![0.0, 0.5, 4.0],
                    _ => vec![0.5, 4.0, 32.0],
                };
            }
        }
        for v in &mut s.grid_variants {
            for tune in v.tune.values_mut() {
                for (name, values) in tune.iter_mut() {
                    *values = match name.as_str() {
                        "c" => vec![0.0, 0.5, 4.0],
                        _ => vec![0.5, 4.0, 32.0],
                    };
                }
            }
        }
        s
    }

    /// Reads settings from a TOML file; errors name file, line and field.
    /// The `plugins = [...]` the file lists are loaded first, so methods may
    /// name plugin policy types.
    pub fn load(path: &Path) -> Result<Self> {
        let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
        crate::load_plugins(&text, path)?;
        let mut s: Self = hil_config::parse_toml(&text, path)?;
        s.check_counts()
            .map_err(|e| hil_config::error_in_section(&text, path, &[], e))?;
        // Paths in the file are relative to the file.
        let base = path.parent().unwrap_or(Path::new(""));
        if let Some(d) = &mut s.dataset {
            *d = base.join(&*d);
        }
        s.check_components()
            .map_err(|e| hil_config::error_in_section(&text, path, &[], e))?;
        // The split's foods against the dataset it names, here where the
        // text is at hand, so an unknown food names its line.
        let ds = s
            .load_dataset()
            .map_err(|e| hil_config::error_at_key(&text, path, &["dataset"], e.to_string()))?;
        s.split
            .validate(&ds)
            .map_err(|e| hil_config::error_in_section(&text, path, &[], e))?;
        for m in &mut s.models {
            if let Some(f) = &mut m.file {
                *f = base.join(&*f);
            }
        }
        Ok(s)
    }

    /// Checks every count against its stated limit
    /// ([`hil_config::limits`]; seeds: at most [`hil_config::limits::SEEDS`]).
    pub fn check_counts(&self) -> Result<()> {
        use hil_config::limits::{ITEMS_PER_EPISODE, SEEDS, check_at_most, check_count};
        check_count(
            "items_per_episode",
            self.items_per_episode,
            ITEMS_PER_EPISODE,
        )?;
        check_count("n_seeds", self.n_seeds, SEEDS)?;
        check_at_most("many_seeds", self.many_seeds, SEEDS)?;
        check_count("n_policy_seeds", self.n_policy_seeds, SEEDS)?;
        Ok(())
    }

    /// The dataset the settings name (the bundled one if none).
    pub fn load_dataset(&self) -> Result<Arc<FoodDataset>> {
        match &self.dataset {
            Some(p) => Ok(Arc::new(FoodDataset::load(p)?)),
            None => hil_envs::bundled_dataset(),
        }
    }

    /// The workload models the settings name, loaded (a `config` model is
    /// built with the settings' seed).
    pub fn load_models(&self) -> Result<Vec<NamedModel>> {
        let ctx = BuildContext::new(".", self.seed);
        self.models
            .iter()
            .enumerate()
            .map(|(i, m)| m.load_with(i, &ctx))
            .collect()
    }

    /// The channel factory the settings name: their `channel` table's type,
    /// or the paper's perfect expert.
    pub fn channel_factory(&self) -> Result<SharedChannelFactory> {
        Ok(match &self.channel {
            Some(t) => Arc::new(ConfiguredChannel::new(t.clone())?),
            None => Arc::new(PerfectExpertChannel),
        })
    }

    /// The environment factory the settings name: their `environment`
    /// table's type, or the paper's dataset replay.
    pub fn environment_factory(&self) -> Result<SharedEnvironmentFactory> {
        Ok(match &self.environment {
            Some(t) => Arc::new(ConfiguredEnvironment::new(t.clone())?),
            None => Arc::new(DatasetReplay),
        })
    }

    /// The name of the paper's model whose published rows `model` is
    /// compared with (its `paper` field, else its own name).
    pub fn paper_name<'a>(&'a self, model: &'a str) -> &'a str {
        self.models
            .iter()
            .find(|m| m.name == model)
            .and_then(|m| m.paper.as_deref())
            .unwrap_or(model)
    }

    /// Environment seeds run: the many-seed run's if it has more.
    pub fn seeds_run(&self) -> usize {
        self.n_seeds.max(self.many_seeds)
    }

    /// Checks the settings against a dataset and the available models.
    pub fn validate(&self, ds: &FoodDataset, models: &[NamedModel]) -> Result<()> {
        self.split.validate(ds)?;
        self.session.validate()?;
        self.check_counts()?;
        if self.w_tasks.is_empty() || self.w_tasks.iter().any(|w| !(0.0..=1.0).contains(w)) {
            return Err(HilError::invalid_parameter(
                "w_tasks",
                format!("{:?}", self.w_tasks),
                "needs at least one value, each in [0, 1]",
            ));
        }
        if !(0.0..=1.0).contains(&self.cross_w_task) {
            return Err(HilError::invalid_parameter(
                "cross_w_task",
                self.cross_w_task,
                "must be in [0, 1]",
            ));
        }
        if self.methods.is_empty() {
            return Err(HilError::invalid_parameter(
                "methods",
                "[]",
                "needs at least one method",
            ));
        }
        for (i, m) in self.methods.iter().enumerate() {
            if self.methods[..i].iter().any(|o| o.label == m.label) {
                return Err(HilError::invalid_parameter(
                    format!("methods[{i}].label"),
                    &m.label,
                    "labels must be unique",
                ));
            }
            if m.tune.len() > 1 {
                return Err(HilError::invalid_parameter(
                    format!("methods[{i}].tune"),
                    m.tune.keys().cloned().collect::<Vec<_>>().join(", "),
                    "at most one hyperparameter can be tuned per method",
                ));
            }
            for (name, values) in &m.tune {
                if values.is_empty() || values.iter().any(|x| !x.is_finite()) {
                    return Err(HilError::invalid_parameter(
                        format!("methods[{i}].tune.{name}"),
                        format!("{values:?}"),
                        "needs at least one value, each finite",
                    ));
                }
            }
            for point in m.grid() {
                m.config(&point)?;
            }
        }
        if models.is_empty() {
            return Err(HilError::invalid_input("workload models", "none given"));
        }
        for (i, m) in models.iter().enumerate() {
            if models[..i].iter().any(|o| o.name == m.name) {
                return Err(HilError::invalid_parameter(
                    format!("models[{i}].name"),
                    &m.name,
                    "model names must be unique",
                ));
            }
        }
        for c in &self.cross {
            let m = self.method(&c.method).ok_or_else(|| {
                HilError::invalid_parameter("cross.method", &c.method, "no method has that label")
            })?;
            if !m.config(&m.grid()[0])?.uses_workload_forecast() {
                return Err(HilError::invalid_parameter(
                    "cross.method",
                    &c.method,
                    "the method does not read the workload forecast, so deciding with \
                     another model changes nothing",
                ));
            }
            for n in [&c.decide, &c.score] {
                if !models.iter().any(|m| &m.name == n) {
                    return Err(HilError::invalid_parameter(
                        "cross",
                        n,
                        "no workload model of that name is in the protocol",
                    ));
                }
            }
        }
        self.check_components()?;
        for v in self.variants()? {
            for (i, m) in v.methods.iter().enumerate() {
                for point in m.grid() {
                    m.config(&point).map_err(|e| {
                        HilError::invalid_parameter(
                            format!(
                                "grid_variants.{}.tune.{}",
                                v.grid_name, self.methods[i].label
                            ),
                            format!("{point:?}"),
                            e.to_string(),
                        )
                    })?;
                }
            }
        }
        for label in std::iter::once(&self.figures.rollout).chain(&self.figures.workload) {
            if self.method(label).is_none() {
                return Err(HilError::invalid_parameter(
                    "figures",
                    label,
                    "no method has that label",
                ));
            }
        }
        Ok(())
    }

    /// Checks that the `channel` and `environment` tables name known types
    /// with valid parameters (the environment's for both phases).
    pub fn check_components(&self) -> Result<()> {
        self.channel_factory()?;
        if let Some(t) = &self.environment {
            let env = ConfiguredEnvironment::new(t.clone())?;
            for foods in [&self.split.validation, &self.split.test] {
                env.config(foods, self.items_per_episode, self.dataset.as_deref())?;
            }
        }
        Ok(())
    }

    /// The w_task the figures (and the CLI's summary) use: the figure
    /// settings' if the run scores it, else the first w_task.
    pub fn figure_w_task(&self) -> f64 {
        let w = self.figures.w_task;
        if self.w_tasks.iter().any(|x| (x - w).abs() < 1e-9) {
            w
        } else {
            self.w_tasks.first().copied().unwrap_or(w)
        }
    }

    /// The method labelled `label`.
    pub fn method(&self, label: &str) -> Option<&Method> {
        self.methods.iter().find(|m| m.label == label)
    }

    /// Environment seed `i`.
    pub fn env_seed(&self, i: usize) -> u64 {
        splitmix(self.seed, 100 + i as u64)
    }

    /// Policy seed `j`.
    pub fn policy_seed(&self, j: usize) -> u64 {
        splitmix(self.seed, 200 + j as u64)
    }
}

/// Where a protocol's workload model comes from: a bundled model, a model
/// file or a workload-model table of any registered type (built-in, plugin
/// or registered from Python), and the name it is reported under.
///
/// ```toml
/// [[models]]
/// name = "f2_sim"
/// bundled = "f2_sim"
///
/// [[models]]
/// name = "ours"
/// file = "models/our_model.json"   # relative to the settings file
/// paper = "f2_sim"                  # compare with the paper's f2_sim rows
///
/// [[models]]
/// name = "plugin"
/// config = { type = "my_model", rate = 0.2 }   # any registered type
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSource {
    /// The name tables and cross settings use.
    pub name: String,
    /// A bundled model (`hil_workload::bundled::NAMES`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bundled: Option<String>,
    /// A model JSON file (`hil workload fit` or `select` writes them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// A workload-model table (`type = "..."` and its parameters; paths in
    /// it resolve against the working directory).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub config: Option<toml::Table>,
    /// The paper's model (`f1_sim`, `f2_sim`, `f12_sim`) whose published
    /// rows this one is shown beside; default: `name`, and for a bundled
    /// `_steep` variant the model it brackets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paper: Option<String>,
}

impl ModelSource {
    /// A bundled model under its own name; a `_steep` variant is compared
    /// with the paper's rows of the model it brackets.
    pub fn bundled(name: &str) -> Self {
        Self {
            name: name.into(),
            bundled: Some(name.into()),
            file: None,
            config: None,
            paper: match End::split(name) {
                (base, End::Steep | End::Middle) => Some(base.to_string()),
                (_, End::Lean) => None,
            },
        }
    }

    /// A model of a registered type under `name` (`table`: `type = "..."`
    /// and its parameters).
    pub fn configured(name: &str, table: toml::Table) -> Self {
        Self {
            name: name.into(),
            bundled: None,
            file: None,
            config: Some(table),
            paper: None,
        }
    }

    /// Loads the model with seed 0; `index` locates errors (`models[i]`).
    pub fn load(&self, index: usize) -> Result<NamedModel> {
        self.load_with(index, &BuildContext::new(".", 0))
    }

    /// Loads the model, building a `config` model with `ctx`; `index`
    /// locates errors (`models[i]`).
    pub fn load_with(&self, index: usize, ctx: &BuildContext) -> Result<NamedModel> {
        let model: Arc<dyn WorkloadModel> = match (&self.bundled, &self.file, &self.config) {
            (Some(b), None, None) => hil_workload::bundled::load(b)?,
            (None, Some(f), None) => Arc::new(hil_workload::FittedModel::load(f)?),
            (None, None, Some(t)) => {
                let invalid = |why: String| {
                    HilError::invalid_parameter(format!("models[{index}].config"), &self.name, why)
                };
                let config = hil_plugin::component::<_, dyn WorkloadModelConfig>(
                    toml::Value::Table(t.clone()),
                )
                .map_err(|e: toml::de::Error| invalid(e.message().trim().to_string()))?;
                config.validate().map_err(|e| invalid(e.to_string()))?;
                config.build(ctx)?
            }
            _ => {
                return Err(HilError::invalid_parameter(
                    format!("models[{index}]"),
                    &self.name,
                    "give exactly one of `bundled` (a bundled model's name), `file` (a model \
                     JSON file) or `config` (a workload-model table of any registered type)",
                ));
            }
        };
        Ok(NamedModel {
            name: self.name.clone(),
            model,
        })
    }
}

/// A workload model with the name it is reported under.
#[derive(Clone)]
pub struct NamedModel {
    /// Name, e.g. `f1_sim`.
    pub name: String,
    /// The model.
    pub model: Arc<dyn WorkloadModel>,
}

impl std::fmt::Debug for NamedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NamedModel")
            .field("name", &self.name)
            .finish()
    }
}

/// Validation or test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Hyperparameters are chosen here.
    Validation,
    /// Chosen hyperparameters are evaluated here.
    Test,
}

/// Identifies one episode.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunKey {
    /// Phase.
    pub phase: Phase,
    /// Index of the method in [`ProtocolSettings::methods`].
    pub method: usize,
    /// The grid point (tuned hyperparameter and value), if tuned.
    pub point: GridPoint,
    /// Index of the model the policy decides with (methods that read the
    /// workload forecast only).
    pub decide_model: Option<usize>,
    /// Environment seed index.
    pub seed: usize,
    /// Policy seed index (0 for deterministic methods).
    pub policy_seed: usize,
}

/// What one step of a run looked like (enough for plots).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepTrace {
    /// Timestep.
    pub t: Timestep,
    /// Item index.
    pub item_index: usize,
    /// The item's food.
    pub food: String,
    /// A query was asked at this step.
    pub query: bool,
    /// The gap G, if the policy reported it.
    pub gap: Option<f64>,
    /// The threshold G was compared with, if reported.
    pub threshold: Option<f64>,
    /// The attempt succeeded.
    pub success: bool,
}

/// One finished episode.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunRecord {
    /// Which episode.
    pub key: RunKey,
    /// Metrics from hil-core, scored with the session's workload model (the
    /// deciding model, or the first model for methods that do not read it);
    /// [`EpisodeMetrics::rescored`] scores them under any other.
    pub metrics: EpisodeMetrics,
    /// Every step.
    pub steps: Vec<StepTrace>,
}

impl RunRecord {
    /// WL_t under `model` at every timestep 0..=T (the curve the paper plots).
    pub fn workload_curve(&self, model: &dyn WorkloadModel) -> Result<Vec<f64>> {
        let m = &self.metrics;
        (0..=m.t_final)
            .map(|t| hil_core::workload::workload_at(model, m.wl0, &m.queries, t))
            .collect()
    }
}

/// The protocol, ready to run.
pub struct Protocol {
    /// Settings.
    pub settings: ProtocolSettings,
    /// The dataset.
    pub dataset: Arc<FoodDataset>,
    /// Workload models (decision and scoring).
    pub models: Vec<NamedModel>,
    /// Builds the simulated expert of every episode (the paper's: a
    /// perfect expert answering with the best action).
    pub channel: SharedChannelFactory,
    /// Builds the environment of every episode (the paper's: dataset
    /// replay over the phase's foods).
    pub environment: SharedEnvironmentFactory,
    /// Runs the episodes in parallel (default: rayon's pool,
    /// `RAYON_NUM_THREADS` or one worker per core).
    pub runner: Runner,
}

impl std::fmt::Debug for Protocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Protocol")
            .field("settings", &self.settings)
            .field("dataset", &self.dataset.name)
            .field("models", &self.models)
            .field("channel", &self.channel.name())
            .field("environment", &self.environment.name())
            .field("threads", &self.runner.threads())
            .finish()
    }
}

/// Why a job of [`Protocol::run_until_cancelled`] stopped the run.
enum Stop {
    /// The cancel flag was raised before the job started.
    Cancelled,
    /// The job's run failed.
    Failed(HilError),
}

/// How [`Protocol::run_until_cancelled`] ended.
#[derive(Debug)]
pub enum RunOutcome {
    /// Every job ran: the records, in job order.
    Finished(Vec<RunRecord>),
    /// The cancel flag was raised; jobs already started finished, no others
    /// started, and their records are dropped.
    Cancelled {
        /// Jobs finished before the run stopped.
        done: usize,
        /// Jobs the protocol has.
        total: usize,
    },
}

impl Protocol {
    /// The protocol over `dataset` and `models`, with the channel and
    /// environment the settings name (by default the paper's perfect
    /// expert and dataset replay). A settings table that does not name a
    /// known type fails here, by field.
    pub fn new(
        settings: ProtocolSettings,
        dataset: Arc<FoodDataset>,
        models: Vec<NamedModel>,
    ) -> Result<Self> {
        Ok(Self {
            channel: settings.channel_factory()?,
            environment: settings.environment_factory()?,
            settings,
            dataset,
            models,
            runner: Runner::default(),
        })
    }

    /// The protocol over the dataset and workload models `settings` name
    /// (loaded and checked against them).
    pub fn from_settings(settings: ProtocolSettings) -> Result<Self> {
        let dataset = settings.load_dataset()?;
        let models = settings.load_models()?;
        settings.validate(&dataset, &models)?;
        Self::new(settings, dataset, models)
    }

    /// The same protocol with its episodes' query channels built by
    /// `factory` (instead of what the settings name).
    pub fn with_channel(mut self, factory: SharedChannelFactory) -> Self {
        self.channel = factory;
        self
    }

    /// The same protocol with its episodes' environments built by
    /// `factory` (instead of what the settings name).
    pub fn with_environment(mut self, factory: SharedEnvironmentFactory) -> Self {
        self.environment = factory;
        self
    }

    /// The same protocol with its episodes run by `runner` (e.g.
    /// `Runner::new(threads)`); the records do not depend on it.
    pub fn with_runner(mut self, runner: Runner) -> Self {
        self.runner = runner;
        self
    }

    /// Selection, aggregation and the frontier of this protocol's `records`
    /// ([`Reproduction::of`]).
    pub fn reproduction(&self, records: &[RunRecord]) -> Result<Reproduction> {
        Reproduction::of(
            &self.settings,
            &self.models,
            records,
            &self.dataset.provenance,
        )
    }

    /// The build context of every policy: the dataset's actions and
    /// dimension, and the pretraining foods' data.
    pub fn build_context(&self) -> Result<TaskContext> {
        let s = &self.settings;
        let data = pretraining_data(
            &self.dataset,
            &s.split.pretrain,
            PretrainReward::Probability,
            s.seed,
        )?;
        let base = BuildContext::new(".", s.seed);
        let ctx = TaskContext::new(base, self.dataset.actions.clone(), self.dataset.context_dim);
        Ok(ctx.with_pretraining(data.into()))
    }

    /// Every episode the protocol needs, each exactly once.
    pub fn jobs(&self) -> Result<Vec<RunKey>> {
        let s = &self.settings;
        let mut specs: Vec<(usize, GridPoint, Option<usize>, usize)> = Vec::new();
        for (i, m) in s.methods.iter().enumerate() {
            for point in s.run_points(i)? {
                let cfg = m.config(&point)?;
                let n_ps = if cfg.is_stochastic() {
                    s.n_policy_seeds
                } else {
                    1
                };
                if cfg.uses_workload_forecast() {
                    for d in 0..self.models.len() {
                        specs.push((i, point.clone(), Some(d), n_ps));
                    }
                } else {
                    specs.push((i, point.clone(), None, n_ps));
                }
            }
        }
        let mut jobs = Vec::new();
        for phase in [Phase::Validation, Phase::Test] {
            for (method, point, decide_model, n_ps) in &specs {
                for seed in 0..s.seeds_run() {
                    for policy_seed in 0..*n_ps {
                        jobs.push(RunKey {
                            phase,
                            method: *method,
                            point: point.clone(),
                            decide_model: *decide_model,
                            seed,
                            policy_seed,
                        });
                    }
                }
            }
        }
        Ok(jobs)
    }

    /// The episode label and the component seeds of run `key`: environment
    /// seeds crossed with policy seeds, so that every method meets the same
    /// items, images and outcomes (common random numbers).
    pub fn seeds(&self, key: &RunKey) -> (u64, ComponentSeeds) {
        let s = &self.settings;
        let env_seed = s.env_seed(key.seed);
        let label = splitmix(env_seed, key.policy_seed as u64);
        let seeds = ComponentSeeds {
            environment: env_seed,
            policy: s.policy_seed(key.policy_seed),
            channel: ComponentSeeds::derive(label).channel,
        };
        (label, seeds)
    }

    /// `e`, raised by run `key`, naming the run: a component's failure
    /// (a backend or query channel, e.g. a Python component's exception, or
    /// a refused input) keeps its kind and source; anything else becomes a
    /// protocol state error.
    fn in_run(&self, key: &RunKey, e: HilError) -> HilError {
        let m = &self.settings.methods[key.method];
        let point = key.point.as_ref().map_or(String::new(), |(name, value)| {
            format!(" at {name} = {value}")
        });
        let run = format!(
            "run of `{}`{point} ({:?}, seed {}, policy seed {})",
            m.label, key.phase, key.seed, key.policy_seed
        );
        match e {
            // Structured refusals (e.g. a policy's arm out of range): the
            // kind and its fields are what callers match.
            e @ (HilError::ArmOutOfRange { .. } | HilError::DimensionMismatch { .. }) => e,
            HilError::InvalidInput { what, why } => HilError::InvalidInput {
                what,
                why: format!("{why} (in the {run})"),
            },
            HilError::Backend {
                backend,
                why,
                source,
            } => HilError::Backend {
                backend,
                why: format!("{why} (in the {run})"),
                source,
            },
            HilError::Channel {
                channel,
                why,
                source,
            } => HilError::Channel {
                channel,
                why: format!("{why} (in the {run})"),
                source,
            },
            e => HilError::state("protocol", format!("{run} failed: {e}")),
        }
    }

    /// Runs one episode.
    pub fn run_one(&self, key: &RunKey, ctx: &TaskContext) -> Result<RunRecord> {
        let s = &self.settings;
        let foods = match key.phase {
            Phase::Validation => &s.split.validation,
            Phase::Test => &s.split.test,
        };
        let method = s.methods.get(key.method).ok_or_else(|| {
            HilError::invalid_parameter("method", key.method, "no method at that index")
        })?;
        // A key from outside `jobs()` (hil-py's protocol_run_json takes
        // JSON) must name a run this protocol has.
        let index = |name: &str, i: usize, n: usize, what: &str| {
            if i < n {
                Ok(())
            } else {
                Err(HilError::invalid_parameter(
                    name,
                    i,
                    format!("this protocol has {n} {what} (indices from 0)"),
                ))
            }
        };
        index("seed", key.seed, s.seeds_run(), "environment seeds")?;
        index(
            "policy_seed",
            key.policy_seed,
            s.n_policy_seeds,
            "policy seeds",
        )?;
        if let Some(d) = key.decide_model {
            index("decide_model", d, self.models.len(), "workload models")?;
        }
        let (label, seeds) = self.seeds(key);
        let mut env = self.environment.build(&EpisodeSpec {
            dataset: &self.dataset,
            dataset_path: s.dataset.as_deref(),
            phase: key.phase,
            foods,
            items_per_episode: s.items_per_episode,
            seed: seeds.environment,
        })?;
        check_matches_task(env.as_ref(), ctx, &self.environment.name())?;
        let mut policy = method.config(&key.point)?.build(ctx)?;
        let mut channel = self.channel.build(ctx)?;
        // Methods that ignore the forecast are scored with the first model;
        // the tables rescore every run under each model anyway.
        let model = self.models[key.decide_model.unwrap_or(0)].model.clone();
        let mut session = Session::new(
            s.session.clone(),
            env.as_mut(),
            policy.as_mut(),
            channel.as_mut(),
            model,
        );
        let report = session.run_episode_with_seeds(label, seeds, &mut [])?;
        let steps = report
            .events
            .iter()
            .map(|e| {
                let st = &e.step;
                StepTrace {
                    t: st.t,
                    item_index: st.item_index,
                    food: st.item_label.clone(),
                    query: matches!(st.decision, StepDecision::Query { .. }),
                    gap: st.diagnostics.as_ref().and_then(|d| d.gap),
                    threshold: st.diagnostics.as_ref().and_then(|d| d.threshold),
                    success: e.outcome.success,
                }
            })
            .collect();
        Ok(RunRecord {
            key: key.clone(),
            metrics: report.metrics,
            steps,
        })
    }

    /// Runs every job in parallel on the protocol's [`Runner`], calling
    /// `progress(done, total)` after each, and returns the records in job
    /// order. The first failing run's error is returned, naming the run.
    pub fn run_all(&self, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<Vec<RunRecord>> {
        match self.run_until_cancelled(progress, &AtomicBool::new(false))? {
            RunOutcome::Finished(records) => Ok(records),
            RunOutcome::Cancelled { .. } => unreachable!("nothing raises this cancel flag"),
        }
    }

    /// [`Protocol::run_all`] that stops early once `cancel` is raised (e.g.
    /// by a Ctrl-C handler on another thread): every job checks the flag
    /// before it starts, so the run ends within one episode per worker
    /// thread, as [`RunOutcome::Cancelled`].
    pub fn run_until_cancelled(
        &self,
        progress: &(dyn Fn(usize, usize) + Sync),
        cancel: &AtomicBool,
    ) -> Result<RunOutcome> {
        self.settings.validate(&self.dataset, &self.models)?;
        let jobs = self.jobs()?;
        let ctx = self.build_context()?;
        // Build every grid point once before running anything, so a value
        // the policy refuses (e.g. a negative w) fails at once, by name.
        for m in &self.settings.methods {
            for point in m.grid() {
                m.config(&point)?.build(&ctx).map_err(|e| {
                    HilError::invalid_parameter(
                        format!("methods.{}", m.label),
                        point
                            .as_ref()
                            .map_or("the policy".into(), |(n, v)| format!("{n} = {v}")),
                        e.to_string(),
                    )
                })?;
            }
        }
        let total = jobs.len();
        let done = AtomicUsize::new(0);
        // The runner stops handing out jobs at the first `Stop`.
        let records = self.runner.map(&jobs, |key| {
            if cancel.load(Ordering::Relaxed) {
                return Err(Stop::Cancelled);
            }
            let r = self.run_one(key, &ctx).map_err(|e| self.in_run(key, e));
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            r.map_err(Stop::Failed)
        });
        match records {
            Ok(records) => Ok(RunOutcome::Finished(records)),
            Err(Stop::Failed(e)) => Err(e),
            Err(Stop::Cancelled) => Ok(RunOutcome::Cancelled {
                done: done.into_inner(),
                total,
            }),
        }
    }
}
