//! `hil workload seeds --write-doc FILE` keeps the printed report as a
//! results page naming the command, so a README can cite the page instead
//! of hand-typed figures.

use crate::common::hil;

#[test]
fn write_doc_keeps_the_printed_report_and_the_command() {
    let dir = std::env::temp_dir().join(format!("hil-workload-seeds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let page = dir.join("results").join("seeds.md");
    let out = hil(&[
        "workload",
        "seeds",
        "--count",
        "2",
        "--write-doc",
        page.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = String::from_utf8(out.stdout).unwrap();
    assert!(report.contains("over 2 generator seeds"), "{report}");
    assert!(report.contains("synthetic"), "{report}");
    let md = std::fs::read_to_string(&page).unwrap();
    assert!(md.contains(&format!("```text\n{report}```")), "{md}");
    assert!(
        md.contains("hil workload seeds --count 2 --write-doc"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
