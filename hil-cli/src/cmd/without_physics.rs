//! `hil kinova ...` and `hil demo kinova` in a build without the `physics`
//! feature: the commands stay listed, take any arguments, and fail saying
//! how to get the MuJoCo simulation (the message is the kinova crate's own,
//! [`hil_kinova_mujoco::ENABLE_PHYSICS`]).

use hil_core::{HilError, Result};

/// Arguments of `hil kinova` (this build has no physics: any are taken).
#[derive(Debug, clap::Args)]
pub struct KinovaArgs {
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    args: Vec<String>,
}

/// Arguments of `hil demo` (this build has no physics: any are taken).
pub type DemoArgs = KinovaArgs;

/// `hil kinova ...`: fails with how to enable it.
pub fn kinova(_: KinovaArgs) -> Result<()> {
    Err(unsupported("hil kinova"))
}

/// `hil demo ...`: fails with how to enable it.
pub fn demo(_: DemoArgs) -> Result<()> {
    Err(unsupported("hil demo"))
}

fn unsupported(command: &str) -> HilError {
    HilError::unsupported(
        "this build of hil",
        format!("`{command}`"),
        hil_kinova_mujoco::ENABLE_PHYSICS,
    )
}
