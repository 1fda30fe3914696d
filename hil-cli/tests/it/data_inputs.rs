//! Every kind of data file `hil` reads for the workload and dataset
//! commands (study CSV, model JSON, dataset manifest, `.npy` array) given
//! as `/dev/zero`, a FIFO or a directory: a clean error naming the file,
//! without reading it (reading `/dev/zero` would grow memory until the
//! process is killed; opening a FIFO would block forever). And `hil
//! workload summary` reports a dataset it cannot build instead of dropping
//! it.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::hil;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-data-inputs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The special files: `/dev/zero`, a FIFO and a directory, all made or
/// found under `dir`.
fn special_files(dir: &Path) -> Vec<PathBuf> {
    let fifo = dir.join("fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let sub = dir.join("a-directory");
    std::fs::create_dir_all(&sub).unwrap();
    vec![PathBuf::from("/dev/zero"), fifo, sub]
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The command failed (not a crash: exit code 1 with hil's error line) and
/// said it was reading `path`, which is not a regular file.
fn assert_refused(out: &Output, path: &Path) {
    let e = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!("reading {}", path.display())) && e.contains("not a regular file"),
        "{e}"
    );
}

const STUDY_HEADER: &str = "participant,population,condition,query_time_s,difficulty,response_type,distraction,interval_min,mental,temporal,performance,effort,frustration,survey_time_s";

#[test]
fn study_csv_that_is_not_a_file_is_refused() {
    let dir = temp_dir("study");
    for p in special_files(&dir) {
        let out = hil(&["workload", "summary", "--data", p.to_str().unwrap()]);
        assert_refused(&out, &p);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn model_json_that_is_not_a_file_is_refused() {
    let dir = temp_dir("model");
    for p in special_files(&dir) {
        let out = hil(&["workload", "rollout", "--model", p.to_str().unwrap()]);
        assert_refused(&out, &p);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn dataset_manifest_that_is_not_a_file_is_refused() {
    let dir = temp_dir("manifest");
    for p in special_files(&dir) {
        // A dataset directory whose `dataset.toml` is the special file.
        let ds = dir.join(format!("ds-{}", p.file_name().unwrap().to_string_lossy()));
        std::fs::create_dir_all(&ds).unwrap();
        let manifest = ds.join("dataset.toml");
        if p.is_dir() {
            std::fs::create_dir_all(&manifest).unwrap();
        } else {
            std::os::unix::fs::symlink(&p, &manifest).unwrap();
        }
        let out = hil(&["data", "check", ds.to_str().unwrap()]);
        assert_refused(&out, &manifest);
        // The special file named directly as the manifest.
        if !p.is_dir() {
            let out = hil(&["data", "check", p.to_str().unwrap()]);
            assert_refused(&out, &p);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A small dataset written by `hil data generate`, whose first food's
/// `field` array is `array` (no field: left valid).
fn dataset_with(dir: &Path, field: &str, array: &Path) -> PathBuf {
    let out = hil(&[
        "data",
        "generate",
        "--out",
        dir.to_str().unwrap(),
        "--images-per-setting",
        "1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let manifest = dir.join("dataset.toml");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let prefix = format!("{field} = \"");
    let mut replaced = field.is_empty();
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if !replaced && l.starts_with(&prefix) {
                replaced = true;
                format!("{field} = \"{}\"", array.display())
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(replaced, "no `{field}` array in {text}");
    std::fs::write(&manifest, lines.join("\n")).unwrap();
    dir.to_path_buf()
}

#[test]
fn npy_array_that_is_not_a_file_is_refused() {
    let dir = temp_dir("npy");
    let ok = dataset_with(&dir.join("ok"), "", Path::new(""));
    let out = hil(&["data", "check", ok.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    for p in special_files(&dir) {
        for field in ["contexts", "success", "settings"] {
            let ds = dataset_with(
                &dir.join(format!(
                    "{field}-{}",
                    p.file_name().unwrap().to_string_lossy()
                )),
                field,
                &p,
            );
            let out = hil(&["data", "check", ds.to_str().unwrap()]);
            assert_refused(&out, &p);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn workload_summary_reports_a_dataset_it_cannot_build() {
    let dir = temp_dir("summary");
    // p1 has a baseline survey, p2 (also D1) has query rows only: WL_0 of
    // p2 is unknown, so D1 and D12 cannot be built.
    let text = format!(
        "{STUDY_HEADER}\n\
         p1,no_limitation,base,330,,,easy,,2,1,4,2,1,\n\
         p1,no_limitation,c1,60,easy,mcq,none,1,3,2,4,3,1,12.5\n\
         p2,no_limitation,c1,60,hard,mcq,none,1,3,2,4,3,1,12.5\n"
    );
    let bad = dir.join("no_baseline.csv");
    std::fs::write(&bad, &text).unwrap();
    let out = hil(&["workload", "summary", "--data", bad.to_str().unwrap()]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!("{}:4: field `participant`", bad.display())) && e.contains("`p2`"),
        "{e}"
    );
    assert!(out.stdout.is_empty(), "no partial summary");

    // Without p2 the study is fine; its D2 is empty (no such participants),
    // which is not an error: the summary shows D1 and D12.
    let good = dir.join("d1_only.csv");
    let text: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(&good, text).unwrap();
    let out = hil(&["workload", "summary", "--data", good.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let o = String::from_utf8_lossy(&out.stdout);
    assert!(
        o.contains("D1: 1 pairs") && o.contains("D12: 1 pairs") && !o.contains("D2:"),
        "{o}"
    );

    // A study of baseline surveys only has nothing to summarise: an error.
    let none = dir.join("baseline_only.csv");
    std::fs::write(
        &none,
        format!("{STUDY_HEADER}\np1,no_limitation,base,330,,,easy,,2,1,4,2,1,\n"),
    )
    .unwrap();
    let out = hil(&["workload", "summary", "--data", none.to_str().unwrap()]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("no query rows"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
