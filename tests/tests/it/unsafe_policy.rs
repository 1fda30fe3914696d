//! `unsafe` appears nowhere in hil-core and the crates split from it except
//! the plugin loader (and the `#[unsafe(no_mangle)]` of the declaration
//! `declare_plugin!` exports).

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
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for krate in [
        "hil-core",
        "hil-config",
        "hil-plugin",
        "hil-conformance",
        "hil-textdata",
    ] {
        rust_files(&root.join(krate).join("src"), &mut files);
    }
    assert!(
        files.len() > 30,
        "hil sources not found under {}",
        root.display()
    );
    let allowed = ["hil-plugin/src/loader.rs", "hil-plugin/src/lib.rs"];
    let mut offenders = Vec::new();
    for f in files {
        let rel = f.strip_prefix(&root).unwrap().to_string_lossy().to_string();
        if allowed.contains(&rel.as_str()) {
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
        "unsafe outside the plugin loader: {offenders:#?}"
    );
}
