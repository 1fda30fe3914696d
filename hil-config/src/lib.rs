//! # hil-config
//!
//! The configuration layer of **hil**: what component factories are built
//! from ([`BuildContext`], [`TaskContext`], [`BuildMemo`]), the four
//! component-config traits ([`PolicyConfig`], [`EnvironmentConfig`],
//! [`WorkloadModelConfig`], [`QueryChannelConfig`]) that typetag names in
//! TOML files, and the locator that turns a parse or validation error into
//! a [`ConfigError`](hil_core::ConfigError) naming the file, line and field
//! ([`parse_toml`], [`error_in_section`], [`error_at_key`]).
//!
//! The experiment file itself, `hil_experiments::ExperimentConfig`, lives
//! with the protocols: it names plugin types, so it sits above the plugin
//! host (`hil-plugin`), which in turn builds on this crate's traits.
//!
//! ```toml
//! seed = 7
//! episodes = 3
//!
//! [session]
//! n_att = 10
//! wl0 = 0.5
//!
//! [environment]
//! type = "food_replay"     # any registered EnvironmentConfig
//!
//! [policy]
//! type = "linucb_qg"
//! alpha = 0.1
//!
//! [workload]               # the model that evolves and scores workload
//! type = "granger"
//!
//! [channel]
//! type = "simulated_expert"
//! ```
//!
//! Crates register built-in types with `#[typetag::serde(name = "...")]` on
//! an `impl PolicyConfig for ...` (or the other three config traits). A
//! program holds the types of the crates linked into it, with no call to
//! make: `hil_experiments` links every built-in crate, so a program that
//! reads configs through `hil_experiments::load_experiment` (or uses that
//! crate at all) knows every built-in type. The names a program holds are
//! `hil_plugin::builtin_types`; a plugin cannot take one of them, and
//! an unknown `type` is answered with the closest built-in and plugin names.
//!
//! `ExperimentConfig::parse` checks the whole file before anything is
//! built: every count against the limits stated in [`limits`], and every
//! component's parameters through its config's `validate`. Any error is a
//! [`ConfigError`](hil_core::ConfigError) naming the file, line and field, and quotes an offending
//! value shortened by [`hil_core::error::echo`].

mod component;
mod context;
mod field_path;
pub mod limits;
mod locate;

pub use component::{
    EnvironmentConfig, ExpertRate, PolicyConfig, QueryChannelConfig, WorkloadModelConfig,
};
pub use context::{BuildContext, BuildMemo, TaskContext};
pub use locate::{error_at_key, error_in_section, parse_toml};

use hil_core::{Result, SessionSettings};

/// Checks the counts of session settings against [`limits`](limits)
/// (`n_att` ≤ [`limits::ATTEMPTS_PER_ITEM`], `max_items` ≤
/// [`limits::ITEMS_PER_EPISODE`]); every loader of session settings calls it
/// after [`SessionSettings::validate`].
pub fn check_session_limits(settings: &SessionSettings) -> Result<()> {
    limits::check_count("n_att", settings.n_att, limits::ATTEMPTS_PER_ITEM)?;
    if let Some(n) = settings.max_items {
        limits::check_count("max_items", n, limits::ITEMS_PER_EPISODE)?;
    }
    Ok(())
}
