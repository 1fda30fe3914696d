//! `hil kinova calibrate` and `hil demo kinova` through the binary (small
//! runs: the full ones take minutes).

mod common;
use common::hil;

#[test]
fn calibrate_prints_rates_beside_the_published_ones() {
    let log =
        std::env::temp_dir().join(format!("hil-kinova-attempts-{}.jsonl", std::process::id()));
    // Three trials: one per setting, so the published `all` row applies.
    let out = hil(&[
        "kinova",
        "calibrate",
        "--trials",
        "3",
        "--foods",
        "carrot",
        "--json",
        "--quiet",
        "--attempts",
        log.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert_eq!(rows[1]["action"], "VS90");
    assert_eq!(rows[1]["published"], 0.53);
    let by_setting = rows[1]["by_setting"].as_array().unwrap();
    assert_eq!(by_setting.len(), 3);
    assert_eq!(by_setting[0]["setting"], "isolated");
    assert_eq!(by_setting[0]["published"], 1.0);
    let attempts = std::fs::read_to_string(&log).unwrap();
    let _ = std::fs::remove_file(&log);
    assert_eq!(attempts.lines().count(), 18);
    let first: serde_json::Value = serde_json::from_str(attempts.lines().next().unwrap()).unwrap();
    assert_eq!(first["food"], "carrot");
    assert!(first["report"]["stop"].is_string());
    assert!(
        rows.iter()
            .all(|r| (0.0..=1.0).contains(&r["rate"].as_f64().unwrap()))
    );
    assert!(v["attempts_per_second"].as_f64().unwrap() > 0.0);

    let out = hil(&["kinova", "calibrate", "--foods", "kiwi"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("kiwi"));
    let out = hil(&["kinova", "calibrate", "--settings", "bowl"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("bowl"));
}

#[test]
fn the_demo_runs_the_protocol_and_renders_or_says_why_not() {
    let dir = std::env::temp_dir().join(format!("hil-kinova-demo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let components = dir.join("components.toml");
    std::fs::write(
        &components,
        "[environment]\npretraining_trials = 0\ncontext_dim = 8\n\
         [linucb]\ntype = \"linucb\"\nalpha = 0.5\n\
         [always_query]\ntype = \"always_query\"\nalpha = 0.5\n\
         [linucb_qg]\ntype = \"linucb_qg\"\nalpha = 0.5\nw = 0.3\n",
    )
    .unwrap();
    let frames = dir.join("frames");
    let out = hil(&[
        "demo",
        "kinova",
        "--repetitions",
        "1",
        "--n-att",
        "1",
        "--json",
        "--quiet",
        "--components",
        components.to_str().unwrap(),
        "--render",
        frames.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let plates = v["plates"].as_array().unwrap();
    assert_eq!(plates.len(), 3);
    let methods: Vec<&str> = plates
        .iter()
        .map(|p| p["method"].as_str().unwrap())
        .collect();
    assert_eq!(methods, ["LinUCB", "AlwaysQuery", "LinUCB-QG"]);
    // LinUCB never asks; AlwaysQuery asks about every item.
    assert_eq!(plates[0]["n_q"], 0);
    assert_eq!(plates[1]["n_q"], 3);
    // Five keyframes per attempt, or a clear note that EGL is unavailable.
    let pngs = std::fs::read_dir(&frames)
        .map(|d| {
            d.filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "png"))
            })
            .count()
        })
        .unwrap_or(0);
    assert!(
        pngs == 5 * 9 || stderr.contains("rendering unavailable"),
        "{pngs} pictures; {stderr}"
    );

    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[polcy]\n").unwrap();
    let out = hil(&["demo", "kinova", "--components", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("polcy"));
    std::fs::remove_dir_all(&dir).ok();
}
