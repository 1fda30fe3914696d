//! One module per subcommand.

pub mod kinova;
pub mod run;
