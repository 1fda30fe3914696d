//! `unsafe` appears nowhere in hil-core except the plugin loader.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn unsafe_only_in_the_plugin_loader() {
    let core = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-core/src");
    let mut files = Vec::new();
    rust_files(&core, &mut files);
    assert!(
        files.len() > 10,
        "hil-core sources not found at {}",
        core.display()
    );
    let mut offenders = Vec::new();
    for f in files {
        let rel = f.strip_prefix(&core).unwrap().to_string_lossy().to_string();
        if rel.starts_with("plugin") {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let words = code.split(|c: char| !(c.is_alphanumeric() || c == '_'));
            if words.into_iter().any(|w| w == "unsafe") && !code.contains("unsafe_code") {
                offenders.push(format!("{rel}:{}: {line}", i + 1));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "unsafe outside hil-core/src/plugin: {offenders:#?}"
    );
}
