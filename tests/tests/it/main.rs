//! The integration tests of `tests`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod common;
mod config_fuzz;
mod config_limits;
mod generated_tests_name_the_property;
mod plugin_config;
mod plugin_drop_panics;
mod plugin_loading;
mod plugin_panics;
mod plugin_static_equivalence;
mod plugins_guide;
mod plugins_guide_blank_folder;
mod unsafe_policy;
