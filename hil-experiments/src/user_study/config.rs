//! The user-study file: which environment, workload model, channel and
//! methods, and how many repetitions.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use hil_config::{BuildContext, EnvironmentConfig, QueryChannelConfig, WorkloadModelConfig};
use hil_core::{ConfigError, HilError, Result, SessionSettings};
use hil_paper::user_study as paper_study;

use crate::method::Method;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize};

/// The real-robot user study of the paper as a config: every component by
/// its `type` (built-in or registered by a plugin), and the methods the
/// participant meets, each as many times as `repetitions` says.
///
/// Every key is optional: what a file leaves out is the paper's protocol
/// ([`UserStudyConfig::paper`]). A component table (`[environment]`,
/// `[workload]`, `[channel]`) or the `methods` array replaces the default
/// as a whole, because another `type` has other parameters; `[session]` is
/// merged key by key over the paper's session (N_att = 3, WL_0 = 0.5), so
/// `wl0 = 0.4` alone keeps N_att = 3.
///
/// ```
/// use hil_experiments::user_study::UserStudyConfig;
/// let cfg = UserStudyConfig::parse(
///     "repetitions = 1\n[channel]\ntype = \"simulated_expert\"\nerror_rate = 0.1\n\
///      [environment]\ntype = \"food_replay\"\nfoods = [\"banana\"]\n",
///     "study.toml".as_ref(),
/// )
/// .unwrap();
/// assert_eq!(cfg.repetitions, 1);
/// assert_eq!(cfg.session.n_att, 3); // the paper's, not given in the file
/// assert_eq!(cfg.labels(), ["LinUCB", "AlwaysQuery", "LinUCB-QG"]);
/// ```
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserStudyConfig {
    /// Shared libraries to load before the components are parsed, relative
    /// to the file.
    #[serde(default)]
    pub plugins: Vec<PathBuf>,
    /// Master seed: pretraining data and every plate's seed derive from it.
    #[serde(default = "paper_seed")]
    pub seed: u64,
    /// How many times the participant meets every method (≥ 1); the order
    /// of the methods is counterbalanced across repetitions
    /// ([`crate::user_study::method_order`]).
    #[serde(default = "paper_repetitions")]
    pub repetitions: usize,
    /// Session-loop settings, merged key by key over the paper's.
    #[serde(default = "paper_session", deserialize_with = "session_over_paper")]
    pub session: SessionSettings,
    /// Where the robot acts; built once and shared by every plate, because
    /// building it (e.g. simulating pretraining attempts) may be expensive.
    #[serde(
        default = "paper_environment",
        deserialize_with = "hil_plugin::component"
    )]
    pub environment: Box<dyn EnvironmentConfig>,
    /// The workload model that evolves and scores the participant's
    /// workload, and that the policies forecast with.
    #[serde(default = "paper_workload", deserialize_with = "hil_plugin::component")]
    pub workload: Box<dyn WorkloadModelConfig>,
    /// Who answers queries; a fresh channel is built for every plate.
    #[serde(default = "paper_channel", deserialize_with = "hil_plugin::component")]
    pub channel: Box<dyn QueryChannelConfig>,
    /// The methods compared, in the order of the first repetition. A
    /// method may tune one hyperparameter (`tune = { w = [...] }`): the
    /// value with the highest mean M_wt over the [`Validation`] plates is
    /// used in the study.
    #[serde(default = "paper_methods")]
    pub methods: Vec<Method>,
    /// The simulated validation run that chooses tuned hyperparameters.
    #[serde(default)]
    pub validation: Validation,
}

/// The simulated validation run of a study: before the study, every
/// tuned method runs `plates` plates (on seeds apart from the study's) at
/// every value of its grid, with a fresh policy per value, and the value
/// with the highest mean M_wt(`w_task`) = w_task·r_task_avg − (1 −
/// w_task)·ΔWL is kept — the criterion the simulated testbed selects by.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Validation {
    /// Validation plates per grid value (≥ 1).
    pub plates: usize,
    /// The task weight of the selection criterion, in [0, 1].
    pub w_task: f64,
}

impl Default for Validation {
    fn default() -> Self {
        Self {
            plates: 4,
            // The testbed's figure w_task, used for the study's selection too.
            w_task: hil_paper::simulation::FIGURE_W_TASK,
        }
    }
}

/// Simulated pretraining attempts per (food, action) in the MuJoCo scene:
/// 10 per (food, action), 180 in all, so that the pretrained estimator's
/// confidence bonuses are no longer dominated by the prior.
const PAPER_PRETRAINING_TRIALS: usize = 10;
/// The foods of the pretraining attempts: none of them is on the plate, as
/// in the paper. They are derived kinds (`hil_kinova_mujoco::FoodKind`):
/// published foods with their own colour, their base kind's shape
/// (honeydew from cantaloupe, kiwi from banana, celery from carrot) and
/// mechanics calibrated to their own published rates.
pub const PAPER_PRETRAIN_FOODS: [&str; 3] = ["honeydew", "kiwi", "celery"];
/// The workload model of the study: the paper's simulation model over the
/// 12 query variables, whose weights are positive, so its forecast never
/// falls when a query is asked (the fitted `f12_real` forecasts a lower
/// workload after some queries, which makes LinUCB-QG's gate meaningless).
pub const PAPER_WORKLOAD: &str = "f12_sim";

fn paper_seed() -> u64 {
    7
}
fn paper_repetitions() -> usize {
    2
}
fn paper_session() -> SessionSettings {
    SessionSettings::default()
        .with_n_att(paper_study::N_ATT)
        .with_wl0(paper_study::WL0)
        .with_max_items(None)
}
/// The paper's scene, `kinova_feeding`, read through its config type as a
/// study file would name it: in a build without `physics` that type is a
/// placeholder whose build says how to enable MuJoCo, so the protocol
/// itself needs no physics.
fn paper_environment() -> Box<dyn EnvironmentConfig> {
    // As in the study: one item at a time, alone on the plate.
    let table = serde_json::json!({
        "type": "kinova_feeding",
        "pretraining_trials": PAPER_PRETRAINING_TRIALS,
        "pretrain_foods": PAPER_PRETRAIN_FOODS,
        "settings": ["isolated"],
        "neighbours": false,
    });
    serde_json::from_value(table)
        .expect("hil-kinova-mujoco registers `kinova_feeding` in every build")
}
fn paper_workload() -> Box<dyn WorkloadModelConfig> {
    Box::new(hil_workload::config::BundledModelConfig {
        name: PAPER_WORKLOAD.into(),
    })
}
fn paper_channel() -> Box<dyn QueryChannelConfig> {
    Box::new(hil_channels::SimulatedExpertConfig::default())
}

fn paper_methods() -> Vec<Method> {
    // The methods the study ran, in the order of its published table; QG's
    // w over the testbed's grid.
    paper_study::OBJECTIVE
        .iter()
        .map(|row| Method::paper(row.method))
        .collect()
}

/// `[session]`: the given keys over the paper's session.
fn session_over_paper<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<SessionSettings, D::Error> {
    let given = toml::Table::deserialize(d)?;
    let mut merged = toml::Table::try_from(paper_session()).map_err(D::Error::custom)?;
    merged.extend(given);
    SessionSettings::deserialize(toml::Value::Table(merged))
        .map_err(|e| D::Error::custom(e.message().trim()))
}

impl Default for UserStudyConfig {
    fn default() -> Self {
        Self::paper()
    }
}

impl UserStudyConfig {
    /// The paper's real-robot protocol, in the MuJoCo scene: a plate of
    /// banana, baby carrot and cantaloupe, each item alone on the plate
    /// (`kinova_feeding`, `isolated`, 10 simulated pretraining attempts per
    /// food and action on foods off the plate, [`PAPER_PRETRAIN_FOODS`]); N_att = 3, WL_0 = 0.5; LinUCB, AlwaysQuery and
    /// LinUCB-QG (α = 0.5, pretrained, w chosen from [`hil_paper::methods::QG_W_GRID`] by
    /// mean M_wt(0.7) over 4 validation plates per value); the bundled `f12_sim`
    /// workload model (a query never lowers its forecast); a perfect `simulated_expert`
    /// answering; 2 repetitions; seed 7. `examples/configs/user-study.toml`
    /// is this config written out.
    ///
    /// ```
    /// let cfg = hil_experiments::user_study::UserStudyConfig::paper();
    /// assert_eq!((cfg.repetitions, cfg.session.n_att, cfg.seed), (2, 3, 7));
    /// ```
    pub fn paper() -> Self {
        Self::paper_on(paper_environment())
    }

    /// The paper's protocol ([`UserStudyConfig::paper`]) on another
    /// environment: any built-in or plugin environment config, e.g. the
    /// bundled food dataset's replay, which needs no physics.
    ///
    /// ```
    /// use hil_experiments::user_study::UserStudyConfig;
    /// let env = hil_envs::FoodReplayConfig {
    ///     dataset: None,
    ///     foods: vec!["banana".into(), "carrot".into()],
    ///     pretrain_foods: vec!["apple".into(), "kiwi".into()],
    ///     items_per_episode: 3,
    ///     outcomes: Default::default(),
    ///     pretrain_reward: Default::default(),
    /// };
    /// let mut cfg = UserStudyConfig::paper_on(Box::new(env));
    /// cfg.repetitions = 1;
    /// let result = cfg.run(".".as_ref(), |_| {}).unwrap();
    /// assert_eq!(result.plates.len(), 3);
    /// assert_eq!(result.protocol.environment, "food_replay");
    /// ```
    pub fn paper_on(environment: Box<dyn EnvironmentConfig>) -> Self {
        Self {
            plugins: Vec::new(),
            seed: paper_seed(),
            repetitions: paper_repetitions(),
            session: paper_session(),
            environment,
            workload: paper_workload(),
            channel: paper_channel(),
            methods: paper_methods(),
            validation: Validation::default(),
        }
    }

    /// Reads and validates a study file (see [`UserStudyConfig::parse`]).
    pub fn load(path: &Path) -> Result<Self> {
        crate::experiment_config::read_config_file(path, Self::parse)
    }

    /// Parses and validates study TOML; `path` names the file in errors and
    /// is where the `plugins` it lists are resolved from. The plugins are
    /// loaded first, so that plugin types are usable wherever built-in ones
    /// are. Every error names the file, line and field. A build without
    /// the `physics` feature refuses a file that names no `[environment]`,
    /// since the paper's scene is the MuJoCo simulation.
    pub fn parse(text: &str, path: &Path) -> std::result::Result<Self, ConfigError> {
        let cfg: Self = crate::experiment_config::parse_listing_plugins(text, path)?;
        cfg.validate_in(text, path)?;
        if !hil_kinova_mujoco::PHYSICS && !names_environment(text) {
            return Err(hil_config::error_at_key(
                text,
                path,
                &["environment"],
                format!(
                    "name the environment of the study (e.g. `[environment]` with `type = \"food_replay\"`): the default, the MuJoCo `kinova_feeding` scene, cannot run because {}",
                    hil_kinova_mujoco::ENABLE_PHYSICS
                ),
            ));
        }
        Ok(cfg)
    }

    /// Checks what the types alone do not: repetitions ≥ 1, at least one
    /// method, unique non-empty labels, valid session settings.
    pub fn validate(&self) -> Result<()> {
        self.validate_in("", Path::new("<config>"))
            .map_err(|e| HilError::invalid_input(e.field.unwrap_or_default(), e.message))
    }

    fn validate_in(&self, text: &str, path: &Path) -> std::result::Result<(), ConfigError> {
        let at =
            |key: &[&str], msg: &str| hil_config::error_at_key(text, path, key, msg.to_string());
        let located =
            |section: &[&str], e: HilError| hil_config::error_in_section(text, path, section, e);
        self.session
            .validate()
            .and_then(|()| hil_config::check_session_limits(&self.session))
            .map_err(|e| located(&["session"], e))?;
        use hil_config::limits::{EPISODES, check_count};
        check_count("repetitions", self.repetitions, EPISODES).map_err(|e| located(&[], e))?;
        check_count("plates", self.validation.plates, EPISODES)
            .map_err(|e| located(&["validation"], e))?;
        // Every component's parameters, before anything is built, so that a
        // bad value names its line (building checks them again).
        let components: [(&str, Result<()>); 3] = [
            ("environment", self.environment.validate()),
            ("workload", self.workload.validate()),
            ("channel", self.channel.validate()),
        ];
        for (section, checked) in components {
            checked.map_err(|e| located(&[section], e))?;
        }
        if !(0.0..=1.0).contains(&self.validation.w_task) {
            return Err(at(&["validation", "w_task"], "must be in [0, 1]"));
        }
        if self.methods.is_empty() {
            return Err(at(&["methods"], "name at least one method"));
        }
        let mut seen = HashSet::new();
        for (i, m) in self.methods.iter().enumerate() {
            let index = i.to_string();
            // A label error names which method's label it is.
            let at_label = |msg: &str| {
                let mut e = at(&["methods", &index, "label"], msg);
                e.field = Some(format!("methods[{i}].label"));
                e
            };
            if m.label.trim().is_empty() {
                return Err(at_label("must not be empty"));
            }
            if !seen.insert(m.label.as_str()) {
                let msg = format!("`{}` names two methods; labels must be unique", m.label);
                return Err(at_label(&msg));
            }
            if m.tune.len() > 1 || m.tune.values().any(|g| g.is_empty()) {
                return Err(at(
                    &["methods", &index, "tune"],
                    "tune at most one hyperparameter, over at least one value",
                ));
            }
            // The policy's values, at every point of its grid.
            for point in m.grid() {
                let section = match point {
                    None => ["methods", index.as_str(), "policy"],
                    Some(_) => ["methods", index.as_str(), "tune"],
                };
                m.config(&point)
                    .and_then(|c| c.validate())
                    .map_err(|e| located(&section, e))?;
            }
        }
        Ok(())
    }

    /// The method labels, in the order of the first repetition.
    pub fn labels(&self) -> Vec<&str> {
        self.methods.iter().map(|m| m.label.as_str()).collect()
    }

    /// The build context of this study: paths resolve against `base_dir`
    /// (the file's directory), components see the study's seed.
    pub fn context(&self, base_dir: &Path) -> BuildContext {
        BuildContext::new(base_dir, self.seed)
    }

    /// Builds the environment from `[environment]`.
    pub fn build_environment(&self, base_dir: &Path) -> Result<Box<dyn hil_core::Environment>> {
        self.environment.build(&self.context(base_dir))
    }

    /// The config as TOML (components with their `type`), e.g. to record
    /// beside results.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| HilError::serde("user-study config", e))
    }
}

/// Whether study TOML `text` (already parsed once) has an `environment` key.
fn names_environment(text: &str) -> bool {
    toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("environment"))
}
