//! `hil workload seeds --write-doc FILE` keeps the printed report as a
//! results page naming the command, so a README can cite the page instead
//! of hand-typed figures.

use crate::common::report_kept_as_page;

#[test]
fn write_doc_keeps_the_printed_report_and_the_command() {
    let report = report_kept_as_page(
        "workload-seeds",
        &["workload", "seeds", "--count", "2"],
        "hil workload seeds --count 2 --write-doc",
    );
    assert!(report.contains("over 2 generator seeds"), "{report}");
    assert!(report.contains("synthetic"), "{report}");
}
