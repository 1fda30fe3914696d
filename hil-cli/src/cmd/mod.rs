//! One module per subcommand.

pub mod data;
pub mod reproduce;
pub mod run;
pub mod workload;
