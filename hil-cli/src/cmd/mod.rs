//! One module per subcommand.

pub mod bench;
pub mod kinova;
pub mod plugins;
pub mod run;
pub mod workload;
