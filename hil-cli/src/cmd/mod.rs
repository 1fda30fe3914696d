//! One module per subcommand.

pub mod data;
pub mod reproduce;
pub mod plugins;
pub mod bench;
pub mod run;
pub mod workload;
