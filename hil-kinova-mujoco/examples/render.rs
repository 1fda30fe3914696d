//! Renders the keyframes of one attempt:
//! `cargo run -p hil-kinova-mujoco --features render --example render -- out/frames`
use hil_core::{ArmId, Environment};
use hil_kinova_mujoco::{
    KeyframeRecorder, KeyframeWriter, KinovaFeedingConfig, KinovaFeedingEnv, RenderingEnv,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/frames".into());
    let mut env = KinovaFeedingEnv::new(KinovaFeedingConfig::default())?;
    let mut writer = KeyframeWriter::new(dir.as_ref(), env.simulator())?;
    let mut rec = KeyframeRecorder::default();
    rec.set_prefix("example");
    {
        let mut renv = RenderingEnv::new(&mut env, &mut rec);
        renv.reset(1)?;
        renv.next_item()?;
        renv.observe()?;
        let out = renv.execute(ArmId(4))?;
        println!("success: {}", out.success);
    }
    writer.write(&mut rec)?;
    println!("wrote {} frames to {dir}", writer.written());
    Ok(())
}
