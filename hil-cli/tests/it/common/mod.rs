//! Shared by the integration tests that run the `hil` binary.

use std::process::{Command, Output};

/// Runs the built `hil` binary with `args` and returns its output.
pub fn hil(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hil"))
        .args(args)
        .output()
        .expect("the hil binary runs")
}
