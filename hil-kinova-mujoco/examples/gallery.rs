//! Renders the README's pictures: one attempt per action on an isolated
//! cantaloupe cube (the `skewer` keyframe: tines in the item at the end of
//! penetration), TV0 and TV90 at the pre-pose (the fork's γ turns the tine
//! row about the pitched handle while the arm holds the handle), and a
//! held item at the end of the 5 s hold. Close-up camera, 400×300 PNG.
//!
//! `cargo run --release -p hil-kinova-mujoco --features render --example gallery -- hil-kinova-mujoco/docs`
use hil_core::{ArmId, Environment};
use hil_kinova_mujoco::{
    KeyframeRecorder, KeyframeWriter, KinovaFeedingConfig, KinovaFeedingEnv, RenderingEnv, View,
    actions,
};

/// Master seed of every attempt (the item's size and yaw, perception noise).
const SEED: u64 = 3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/gallery".into());
    let mut env = KinovaFeedingEnv::new(KinovaFeedingConfig {
        plate: vec!["cantaloupe".into()],
        settings: vec!["isolated".into()],
        neighbours: false,
        ..KinovaFeedingConfig::default()
    })?;
    let view = View {
        camera: "closeup".into(),
        width: 400,
        height: 300,
    };
    let mut writer = KeyframeWriter::with_view(dir.as_ref(), env.simulator(), &view)?;
    for (a, action) in actions().iter().enumerate() {
        let mut rec = KeyframeRecorder::default();
        rec.set_prefix(action.name.to_lowercase());
        let success = {
            let mut renv = RenderingEnv::new(&mut env, &mut rec);
            renv.reset(SEED)?;
            renv.next_item()?;
            renv.observe()?;
            renv.execute(ArmId(a))?.success
        };
        println!("{}: success {success}", action.name);
        let tv = action.name.starts_with("TV");
        rec.retain(|name| {
            name.ends_with("_skewer")
                || (tv && name.ends_with("_pre_pose"))
                || (action.name == "TV0" && name.ends_with("_hold"))
        });
        writer.write(&mut rec)?;
    }
    // Short names for the README: `{action}_{phase}.png`.
    for entry in std::fs::read_dir(&dir)? {
        let path = entry?.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let parts: Vec<&str> = name.split('_').collect();
        if parts.len() >= 4 && parts[1] == "01" {
            let short = format!("{}_{}", parts[0], parts[3..].join("_"));
            std::fs::rename(&path, path.with_file_name(short))?;
        }
    }
    println!("wrote {} frames to {dir}", writer.written());
    Ok(())
}
