//! One module per subcommand.

pub mod bench;
pub mod data;
pub mod kinova;
pub mod plugins;
pub mod reproduce;
pub mod run;
pub mod workload;
