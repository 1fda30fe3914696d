//! One module per subcommand.

pub mod plugins;
pub mod bench;
pub mod run;
pub mod workload;
