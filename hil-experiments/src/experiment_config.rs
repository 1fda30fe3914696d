//! The experiment file: [`ExperimentConfig`], a TOML file naming an
//! environment, a policy, a workload model and a query channel by type
//! (built-in through typetag, or from the plugins it lists), and how to run
//! them.
//!
//! It lives here rather than in `hil-config` because it names plugin types:
//! its components deserialise through [`hil_plugin::component`], and the
//! plugin host itself builds on `hil-config`'s traits.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use hil_config::limits;
use hil_config::{
    BuildContext, EnvironmentConfig, PolicyConfig, QueryChannelConfig, WorkloadModelConfig,
    check_session_limits, error_at_key, error_in_section, parse_toml,
};
use hil_core::{ConfigError, HilError, Result, SessionSettings};

use crate::experiment::Experiment;

/// A complete experiment: the components and how to run them.
///
/// Read from TOML (see `examples/configs/` for the built-in types); here
/// with components registered in code, as a downstream crate would:
///
/// ```
/// use std::path::Path;
/// use hil_plugin::{self as plugin, Params};
/// use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
/// use hil_core::{ActionSpace, ArmId, Choice, HilError, PerfectExpert};
/// use hil_experiments::ExperimentConfig;
///
/// plugin::register_static(Path::new("experiment-doc"), |r| {
///     r.environment("doc_plate", "two foods", |_p: &Params, _ctx| {
///         let actions = ActionSpace::new(["skewer", "scoop"])?;
///         Ok(Box::new(TableEnv::new(actions, vec![("pea", vec![0.2, 0.9]), ("cube", vec![0.8, 0.3])])?))
///     });
///     r.policy("doc_always_skewer", "always the first action", |_p, ctx| {
///         let first = vec![Choice::Act { arm: ArmId(0) }];
///         Ok(Box::new(ScriptedPolicy::new(ctx.action_space().len(), ctx.context_dim(), first)))
///     });
///     r.workload_model("doc_counting", "a step per query", |_p, _ctx| {
///         Ok(Box::new(CountingWorkload::new(0.1)))
///     });
///     r.query_channel("doc_expert", "the perfect expert", |_p, _ctx| {
///         Ok(Box::new(PerfectExpert::default()))
///     });
/// })?;
///
/// let text = r#"
/// seed = 3
/// episodes = 2
/// [session]
/// n_att = 2
/// [environment]
/// type = "doc_plate"
/// [policy]
/// type = "doc_always_skewer"
/// [workload]
/// type = "doc_counting"
/// [channel]
/// type = "doc_expert"
/// "#;
/// let config = ExperimentConfig::parse(text, Path::new("doc.toml"))?;
/// let mut experiment = config.build(Path::new("."))?;
/// let summary = experiment.run(&mut [], |_, _| {})?;
/// assert_eq!(summary.episodes.len(), 2);
/// assert!(summary.episodes.iter().all(|m| m.n_items == 2 && m.n_q == 0));
///
/// // A mistake is reported with the file, line and field.
/// let e = ExperimentConfig::parse(&text.replace("n_att = 2", "n_att = 0"), Path::new("doc.toml"));
/// assert!(e.unwrap_err().to_string().contains("doc.toml"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    /// Shared libraries to load before the components are built.
    #[serde(default)]
    pub plugins: Vec<PathBuf>,
    /// Master seed; episode `k` runs with a seed derived from it.
    #[serde(default)]
    pub seed: u64,
    /// Number of episodes (the policy keeps learning across them), 1 to
    /// [`limits::EPISODES`](hil_config::limits::EPISODES).
    #[serde(default = "one")]
    pub episodes: usize,
    /// Session-loop settings.
    #[serde(default)]
    pub session: SessionSettings,
    /// Where the robot acts.
    #[serde(deserialize_with = "hil_plugin::component")]
    pub environment: Box<dyn EnvironmentConfig>,
    /// Who decides.
    #[serde(deserialize_with = "hil_plugin::component")]
    pub policy: Box<dyn PolicyConfig>,
    /// The workload model that evolves and scores the person's workload.
    #[serde(deserialize_with = "hil_plugin::component")]
    pub workload: Box<dyn WorkloadModelConfig>,
    /// The model the policy forecasts with, if different from `workload`.
    #[serde(default, deserialize_with = "hil_plugin::optional_component")]
    pub policy_workload: Option<Box<dyn WorkloadModelConfig>>,
    /// How queries reach the expert.
    #[serde(deserialize_with = "hil_plugin::component")]
    pub channel: Box<dyn QueryChannelConfig>,
}

fn one() -> usize {
    1
}

impl ExperimentConfig {
    /// Builds every component. Relative paths resolve against `base_dir`.
    /// The environment is built first, so that the policy and the channel
    /// know its action space and context dimension.
    pub fn build(&self, base_dir: &Path) -> Result<Experiment> {
        self.build_with(base_dir, |_, e| e)
    }

    /// [`build`](Self::build), for the config read from `text` at `path`:
    /// an error raised in building a component (an unknown food, a
    /// bundled model that does not exist, a dataset file that cannot be
    /// read) is located in the file, at the component's key.
    pub fn build_located(&self, base_dir: &Path, text: &str, path: &Path) -> Result<Experiment> {
        self.build_with(base_dir, |section, e| {
            error_in_section(text, path, &[section], e).into()
        })
    }

    fn build_with(
        &self,
        base_dir: &Path,
        locate: impl Fn(&str, HilError) -> HilError,
    ) -> Result<Experiment> {
        let ctx = BuildContext::new(base_dir, self.seed);
        let locate = &locate;
        let at = |section: &'static str| move |e| locate(section, e);
        let environment = self.environment.build(&ctx).map_err(at("environment"))?;
        let task = ctx
            .describe_environment(self.environment.as_ref(), environment.as_ref())
            .map_err(at("environment"))?;
        let policy = self.policy.build(&task).map_err(at("policy"))?;
        let workload = self.workload.build(&ctx).map_err(at("workload"))?;
        let forecast = match &self.policy_workload {
            Some(c) => Some(c.build(&ctx).map_err(at("policy_workload"))?),
            None => None,
        };
        let channel = self.channel.build(&task).map_err(at("channel"))?;
        Ok(Experiment {
            settings: self.session.clone(),
            seed: self.seed,
            episodes: self.episodes,
            environment,
            policy,
            channel,
            workload,
            forecast,
        })
    }

    /// Reads and validates an experiment file.
    pub fn load(path: &Path) -> Result<Self> {
        read_config_file(path, Self::parse)
    }

    /// Parses experiment TOML. `path` names the file in error messages, and
    /// the `plugins` it lists are resolved against its directory and loaded
    /// (see [`hil_plugin::load`]) before the components are parsed, so
    /// plugin types are usable wherever built-in ones are.
    pub fn parse(text: &str, path: &Path) -> std::result::Result<Self, ConfigError> {
        let cfg: Self = parse_listing_plugins(text, path)?;
        let located = |section: &[&str], e: HilError| error_in_section(text, path, section, e);
        limits::check_count("episodes", cfg.episodes, limits::EPISODES)
            .map_err(|e| located(&[], e))?;
        cfg.session
            .validate()
            .and_then(|()| check_session_limits(&cfg.session))
            .map_err(|e| located(&["session"], e))?;
        // Every component's parameters, before anything is built, so that a
        // bad value names its line (`build` checks them again).
        let components: [(&str, Result<()>); 5] = [
            ("environment", cfg.environment.validate()),
            ("policy", cfg.policy.validate()),
            ("workload", cfg.workload.validate()),
            (
                "policy_workload",
                cfg.policy_workload
                    .as_ref()
                    .map_or(Ok(()), |w| w.validate()),
            ),
            ("channel", cfg.channel.validate()),
        ];
        for (section, checked) in components {
            checked.map_err(|e| located(&[section], e))?;
        }
        Ok(cfg)
    }
}

/// Reads a config file (at most [`limits::CONFIG`](hil_core::files::limits::CONFIG)
/// bytes) and parses it with `parse`: the one reader of every TOML file
/// that may list plugins.
pub(crate) fn read_config_file<T>(
    path: &Path,
    parse: impl FnOnce(&str, &Path) -> std::result::Result<T, ConfigError>,
) -> Result<T> {
    let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
    Ok(parse(&text, path)?)
}

/// Loads the `plugins` a config file lists (see [`load_plugins`]), then
/// parses the whole file as `T`, so plugin types are usable wherever
/// built-in ones are.
pub(crate) fn parse_listing_plugins<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &Path,
) -> std::result::Result<T, ConfigError> {
    load_plugins(text, path)?;
    parse_toml(text, path)
}

/// Loads the `plugins` a config file lists (a top-level `plugins` array),
/// relative to the file's directory. Call it before parsing the rest of a
/// config of your own that names plugin types.
pub fn load_plugins(text: &str, path: &Path) -> std::result::Result<(), ConfigError> {
    #[derive(Deserialize)]
    struct PluginsOnly {
        #[serde(default)]
        plugins: Vec<PathBuf>,
    }
    let pre: PluginsOnly = parse_toml(text, path)?;
    let base = path.parent().unwrap_or(Path::new(""));
    for p in &pre.plugins {
        let full = if p.is_absolute() {
            p.clone()
        } else {
            base.join(p)
        };
        hil_plugin::load(&full)
            .map_err(|e| error_at_key(text, path, &["plugins"], e.to_string()))?;
    }
    Ok(())
}
