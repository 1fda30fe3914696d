//! The tests `conformance_tests!` generates for a plugin author's type fail
//! one by one, naming the property: the test plugin
//! `hil-test-plugin-unchecked-context` (a policy that panics on a longer
//! context) fails `rejects_wrong_dimension`, and `rejection_has_no_effect`
//! (the panic leaves it unusable), and passes every other property.

use crate::common;

#[test]
#[ignore = "e2e: needs a nested cargo test of a test plugin; bash scripts/test runs it"]
fn a_policy_that_panics_on_a_longer_context_fails_exactly_its_generated_test() {
    let (target, _) = hil_conformance::cdylib::target_layout().unwrap();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(common::workspace_root())
        .env("CARGO_TARGET_DIR", target.join("plugin-build"))
        .args([
            "test",
            "--quiet",
            "-p",
            "hil-test-plugin-unchecked-context",
            "--features",
            "generated-tests",
            "--lib",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        !out.status.success(),
        "the generated tests passed:\n{stdout}"
    );
    // libtest's report: the failing tests, one per line, under `failures:`.
    let failures: Vec<&str> = stdout
        .rsplit_once("failures:\n")
        .map(|(_, list)| list)
        .unwrap_or_default()
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("tests::"))
        .collect();
    assert_eq!(
        failures,
        [
            "tests::unchecked_linear::rejection_has_no_effect",
            "tests::unchecked_linear::rejects_wrong_dimension"
        ],
        "{stdout}"
    );
    assert!(
        stdout.contains("property `rejects wrong dimension` does not hold for `unchecked_linear`"),
        "{stdout}"
    );
}
