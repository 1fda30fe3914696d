//! A `hil` built without the `speech` feature leaves the speech crate out,
//! yet a config that asks for a spoken channel gets a located error that
//! says how to build one, not an unknown channel type.

use crate::common::hil;

#[test]
fn a_speech_channel_says_how_to_enable_speech() {
    let dir = std::env::temp_dir().join(format!("hil-cli-no-speech-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let quickstart = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/configs/quickstart.toml"
    );
    let text = std::fs::read_to_string(quickstart).unwrap();
    let head = text.split("[channel]").next().unwrap();
    let config = dir.join("spoken.toml");
    std::fs::write(
        &config,
        format!("{head}[channel]\ntype = \"speech\"\nthreshold = 0.5\n"),
    )
    .unwrap();
    let out = hil(&["run", "-c", config.to_str().unwrap(), "-q"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("spoken.toml:"), "{stderr}");
    assert!(stderr.contains("field `channel`"), "{stderr}");
    assert!(stderr.contains("--features speech"), "{stderr}");
    let out = hil(&["bench", "speech"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--features speech"));
    let _ = std::fs::remove_dir_all(dir);
}
