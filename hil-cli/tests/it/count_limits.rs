//! A count flag given a value outside its limit (`hil_config::limits`, or
//! the benchmark's own) is refused before anything is allocated or run,
//! with an error naming the flag: a 20-digit count was a capacity-overflow
//! panic, and a schedule's last timestep + 10 wrapped around to a short,
//! wrong rollout.

use crate::common::hil;

const HUGE: &str = "18446744073709551615";

fn refused(args: &[&str], names: &str) {
    let out = hil(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(stderr.contains(names), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

#[test]
fn counts_outside_their_limits_name_the_flag() {
    refused(&["workload", "seeds", "--count", HUGE], "--count");
    refused(&["workload", "seeds", "--count", "0"], "--count");
    for flag in ["--dim", "--arms", "--steps", "--pretrain"] {
        refused(&["bench", "policy", "--policy", "linucb", flag, HUGE], flag);
    }
    refused(
        &["reproduce", "--quick", "--threads", "100000"],
        "--threads",
    );
    refused(
        &[
            "workload",
            "fit",
            "--data",
            "no-such.csv",
            "--population",
            "d1",
        ]
        .into_iter()
        .chain([
            "--model",
            "granger",
            "--history",
            "100000",
            "--out",
            "x.json",
        ])
        .collect::<Vec<_>>(),
        "history",
    );
    // The options are checked before the library is opened.
    for (flag, value) in [
        ("--dim", HUGE),
        ("--dim", "8193"),
        ("--queries", HUGE),
        ("--queries", "0"),
        ("--attempts", "0"),
        ("--attempts", "1001"),
    ] {
        refused(
            &["plugins", "check", "no-such-plugin.so", flag, value],
            flag,
        );
    }
    let out = std::env::temp_dir().join(format!("hil-count-limits-{}", std::process::id()));
    let out = out.to_str().unwrap();
    refused(&["data", "generate", "--out", out, "--dim", HUGE], "dim");
    refused(
        &[
            "data",
            "generate",
            "--out",
            out,
            "--images-per-setting",
            HUGE,
        ],
        "images_per_setting",
    );
    assert!(!std::path::Path::new(out).exists(), "nothing is written");
    let rollout = |extra: &[&str], names: &str| {
        let mut args = vec!["workload", "rollout", "--model", "bundled:f1_sim"];
        args.extend_from_slice(extra);
        refused(&args, names);
    };
    rollout(&["--schedule", "3", "--steps", HUGE], "steps");
    rollout(&["--schedule", &format!("3,{HUGE}")], "schedule[1]");
}

/// The simulation's commands: `hil kinova calibrate` and `hil demo kinova`.
#[cfg(feature = "physics")]
#[test]
fn kinova_counts_outside_their_limits_name_the_flag() {
    for (flag, value) in [("--seeds", "0"), ("--seeds", HUGE), ("--trials", HUGE)] {
        refused(&["kinova", "calibrate", flag, value], flag);
    }
    for (flag, value) in [
        ("--repetitions", HUGE),
        ("--n-att", "1001"),
        ("--seeds", HUGE),
    ] {
        refused(&["demo", "kinova", flag, value], flag);
    }
}
