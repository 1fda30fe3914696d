//! PLUGINS.md works from a blank folder: its shell steps and files, in
//! order and exactly as written, build a plugin next to a hil checkout
//! (`hil/`, here a link to this workspace), and the README's release `hil`
//! (`hil/scripts/hil`) lists and checks it.

use crate::common;

/// The guide's steps in document order: `Run(script)` for a block after
/// `<!-- guide-run -->`, `Write(path, text)` after `<!-- guide-write: PATH -->`.
#[derive(Debug)]
enum Step {
    Run(String),
    Write(String, String),
}

fn steps(text: &str) -> Vec<Step> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("<!-- guide-") {
        let after = &rest[i + "<!-- guide-".len()..];
        let end = after.find("-->").expect("closed comment");
        let marker = after[..end].trim();
        let body = &after[end..];
        let fence = body.find("```").expect("a fenced block after the marker");
        let block = &body[fence..];
        let first_nl = block.find('\n').expect("fence line");
        let close = block[first_nl + 1..].find("\n```").expect("closing fence") + first_nl + 1;
        let code = block[first_nl + 1..=close].to_string();
        if marker == "run" {
            out.push(Step::Run(code));
        } else if let Some(path) = marker.strip_prefix("write:") {
            out.push(Step::Write(path.trim().to_string(), code));
        }
        // Other markers (guide-file, guide-config) are checked by plugins_guide.rs.
        rest = &after[end..];
    }
    out
}

#[test]
fn the_guide_has_run_and_write_steps() {
    let text = std::fs::read_to_string(common::workspace_root().join("PLUGINS.md")).unwrap();
    let steps = steps(&text);
    let writes: Vec<&str> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Write(p, _) => Some(p.as_str()),
            Step::Run(_) => None,
        })
        .collect();
    assert_eq!(writes, ["my-plugin/Cargo.toml", "my-plugin/src/lib.rs"]);
    assert!(steps.iter().filter(|s| matches!(s, Step::Run(_))).count() >= 4);
}

#[test]
#[ignore = "e2e: needs nested cargo builds (a release hil and the guide's plugin); bash scripts/test runs it"]
fn the_guide_builds_a_plugin_from_a_blank_folder_that_the_release_hil_loads() {
    let text = std::fs::read_to_string(common::workspace_root().join("PLUGINS.md")).unwrap();
    let dir = common::scratch("blank-folder");
    std::os::unix::fs::symlink(common::workspace_root(), dir.join("hil")).unwrap();
    // One script, so a `cd` in one step holds for the next, as in a shell.
    let mut script = String::from("set -euo pipefail\nroot=\"$PWD\"\n");
    for step in steps(&text) {
        match step {
            Step::Run(code) => script.push_str(&code),
            Step::Write(path, code) => script.push_str(&format!(
                "cat > \"$root/{path}\" <<'HIL_GUIDE_EOF'\n{code}HIL_GUIDE_EOF\n"
            )),
        }
    }
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(&script)
        .current_dir(&dir)
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("CARGO_MANIFEST_DIR")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "the guide's steps failed\n--- script\n{script}\n--- stdout\n{stdout}\n--- stderr\n{stderr}"
    );
    assert!(stdout.contains("profile: release"), "{stdout}");
    assert!(stdout.contains("all 1 types conform"), "{stdout}");
    assert!(
        dir.join("my-plugin/target/release")
            .join(format!(
                "{}my_plugin{}",
                std::env::consts::DLL_PREFIX,
                std::env::consts::DLL_SUFFIX
            ))
            .exists()
    );
}
