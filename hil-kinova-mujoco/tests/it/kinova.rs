//! Integration tests of the MuJoCo feeding environment: kinematics against
//! the fact sheet, action execution, determinism, conformance, a session
//! episode, and errors for bad MJCF files.

use std::sync::Arc;

use hil_conformance::check_environment;
use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy};
use hil_core::channel::PerfectExpert;
use hil_core::{
    ArmId, Choice, Difficulty, Distraction, Environment, QueryKind, ResponseType, Session,
    SessionSettings,
};
use hil_kinova_mujoco::{
    FoodKind, FoodModel, KinovaError, KinovaFeedingConfig, KinovaFeedingEnv, MjcfSource, Placement,
    Simulator, actions,
};
use nalgebra::Vector3;
use rand::SeedableRng;

use crate::common::assert_reached;

fn small_env() -> KinovaFeedingEnv {
    KinovaFeedingEnv::new(KinovaFeedingConfig {
        context_dim: 16,
        ..KinovaFeedingConfig::default()
    })
    .expect("built-in scene loads")
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn forward_kinematics_matches_the_fact_sheet() {
    let mut sim = Simulator::new().unwrap();
    let base = {
        let ids = sim.ids().clone();
        let _ = ids;
        // base_link sits on the table at (0, 0, 0.72).
        Vector3::new(0.0, 0.0, 0.72)
    };
    let ee_site = sim
        .data()
        .model()
        .name_to_id(mujoco_rs::prelude::MjtObjBase::mjOBJ_SITE, "end_effector")
        .unwrap();
    let kin = sim.kinematics();
    // q = 0: end_effector_link at (0, 0.0014, 1.1766) above base_link.
    kin.forward(&[0.0; 6], [0.0, 0.0]);
    let ee = kin.site_pos(ee_site) - base;
    assert!(
        (ee - Vector3::new(0.0, 0.0014, 1.1766)).norm() < 1e-3,
        "q=0: {ee:?}"
    );
    // FLAIR's acquisition pose (0..2π values wrapped): fork tip at about
    // (0.314, −0.002, 0.345), tines pointing down.
    let wrap = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    let acq = [0.0296, 0.0665, 5.2812, 3.1258, 2.0499, 4.7379].map(wrap);
    let (tip, base_rot) = kin.forward(&acq, [0.0, 0.0]);
    let tip = tip - base;
    assert!(
        (tip - Vector3::new(0.314, -0.002, 0.345)).norm() < 0.01,
        "acq tip {tip:?}"
    );
    // The fork base's x axis is the handle at β = 0.
    assert!(
        base_rot.column(0).dot(&-Vector3::z()) > 0.99,
        "handle {:?}",
        base_rot.column(0)
    );
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn every_action_reaches_its_commanded_pitch_and_roll() {
    let mut sim = Simulator::new().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for (i, action) in actions().iter().enumerate() {
        let props = FoodModel::default_for(FoodKind::Cantaloupe).sample(&mut rng);
        let yaw = -1.0 + 0.4 * i as f64;
        let items = vec![Placement {
            props,
            xy: [0.01, -0.01],
            yaw,
        }];
        let pose = sim.stage(&items, None, FoodKind::Cantaloupe).unwrap()[0];
        let r = sim.execute(action, &pose.exact_target(), None).unwrap();
        assert_reached(action, "pitch", r.reached_pitch, action.pitch, 0.03);
        assert_reached(action, "roll", r.reached_roll, action.roll, 0.05);
        assert!(r.tines.touched >= 2, "{}: tines {:?}", action.name, r.tines);
    }
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn the_same_seed_replays_the_same_attempts() {
    let run = || {
        let mut env = small_env();
        env.reset(42).unwrap();
        let mut out = Vec::new();
        while let Some(item) = env.next_item().unwrap() {
            let x = env.observe().unwrap();
            let o = env.execute(ArmId(item.index % 6)).unwrap();
            out.push((x, o, env.last_attempt().unwrap().clone()));
        }
        out
    };
    assert_eq!(run(), run());
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn passes_the_environment_conformance_suite() {
    let report =
        check_environment(&|| Ok(Box::new(small_env()) as Box<dyn Environment>), 1).unwrap();
    assert!(!report.passed.is_empty(), "{report:?}");
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn a_short_episode_runs_through_the_session_loop() {
    let mut env = small_env();
    let query = Choice::Query {
        kind: QueryKind {
            response: ResponseType::Mcq,
            difficulty: Difficulty::Easy,
            distraction: Distraction::None,
        },
        fallback: ArmId(0),
    };
    // Ask about the first item, then act on its own with TA0.
    let mut policy = ScriptedPolicy::new(6, 16, vec![query, Choice::Act { arm: ArmId(4) }]);
    let mut channel = PerfectExpert::default();
    let mut session = Session::new(
        SessionSettings::default()
            .with_n_att(2)
            .with_wl0(0.5)
            .with_max_items(Some(2)),
        &mut env,
        &mut policy,
        &mut channel,
        Arc::new(CountingWorkload::new(0.1)),
    );
    let report = session.run_episode(3, &mut []).unwrap();
    assert_eq!(report.metrics.n_items, 2);
    assert_eq!(report.metrics.n_q, 1);
    assert!(report.metrics.n_steps >= 2 && report.metrics.n_steps <= 4);
    assert_eq!(channel.asked, 1);
    // The expert's answer for a banana is the best published action, TA0.
    assert!(policy.feedback.iter().any(|f| f.3 && f.1 == ArmId(4)));
}

#[test]
fn missing_and_malformed_mjcf_files_are_clear_errors() {
    let dir = std::env::temp_dir().join(format!("hil-kinova-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    let missing = dir.join("nope.xml");
    let err = Simulator::from_source(MjcfSource::File(&missing)).unwrap_err();
    assert!(matches!(err, KinovaError::MjcfUnreadable { .. }));
    assert!(err.to_string().contains("nope.xml"), "{err}");

    let bad = dir.join("bad.xml");
    std::fs::write(
        &bad,
        "<mujoco>\n  <worldbody>\n    <body name=\"a\">\n</mujoco>\n",
    )
    .unwrap();
    let err = Simulator::from_source(MjcfSource::File(&bad)).unwrap_err();
    assert!(matches!(err, KinovaError::MjcfMalformed { .. }), "{err}");
    assert!(err.to_string().contains("bad.xml"), "{err}");

    let lacking = dir.join("lacking.xml");
    std::fs::write(
        &lacking,
        "<mujoco><worldbody><geom type=\"sphere\" size=\"0.1\"/></worldbody></mujoco>",
    )
    .unwrap();
    let err = Simulator::from_source(MjcfSource::File(&lacking)).unwrap_err();
    assert!(err.to_string().contains("joint_1"), "{err}");

    // Through the config: the error reaches the caller as a HilError.
    let cfg = KinovaFeedingConfig {
        mjcf: Some(missing.clone()),
        ..KinovaFeedingConfig::default()
    };
    let err = KinovaFeedingEnv::new(cfg).unwrap_err();
    assert!(err.to_string().contains("nope.xml"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn config_rejects_unknown_foods_and_fields() {
    let bad: Result<KinovaFeedingConfig, _> = toml::from_str("plate = [\"apple\"]");
    let err = KinovaFeedingEnv::new(bad.unwrap()).unwrap_err();
    assert!(err.to_string().contains("apple"), "{err}");
    let unknown: Result<KinovaFeedingConfig, _> = toml::from_str("colour = 3");
    assert!(unknown.is_err());
}

/// Stages one carrot in `setting` and returns the environment after `observe`.
fn staged(setting: &str, seed: u64) -> KinovaFeedingEnv {
    let mut env = KinovaFeedingEnv::new(KinovaFeedingConfig {
        plate: vec!["carrot".into()],
        settings: vec![setting.into()],
        context_dim: 16,
        ..KinovaFeedingConfig::default()
    })
    .unwrap();
    env.reset(seed).unwrap();
    env.next_item().unwrap();
    env.observe().unwrap();
    env
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn each_setting_places_the_item_where_it_says() {
    use hil_kinova_mujoco::Setting;
    let plate = Simulator::new().unwrap().plate_top_centre();
    for seed in 0..4 {
        let radial = |env: &KinovaFeedingEnv| {
            let p = env.simulator().true_poses()[0];
            (
                ((p.centre[0] - plate.x).powi(2) + (p.centre[1] - plate.y).powi(2)).sqrt(),
                p.centre[2] - p.half_extents[2] - plate.z,
                p.on_leaf,
            )
        };
        let env = staged("isolated", seed);
        assert_eq!(env.current_setting(), Some(Setting::Isolated));
        let (r, lift, leaf) = radial(&env);
        assert!(r + 0.028 < 0.100, "isolated carrot {r} m from the centre");
        assert!(
            lift.abs() < 0.002 && !leaf,
            "isolated carrot rests on the plate: {lift}"
        );
        // Against the rim: the carrot's side is within 3 mm of the rim's foot
        // (radius 0.094) or already on its slope.
        let (r, _, _) = radial(&staged("wall", seed));
        assert!(r > 0.080, "wall carrot {r} m from the centre");
        // On the leaf: raised by the leaf and its midrib.
        let env = staged("lettuce", seed);
        let (_, lift, leaf) = radial(&env);
        assert!(leaf && lift > 0.002, "lettuce carrot raised {lift} m");
        assert!(
            env.current_item()
                .unwrap()
                .description
                .as_deref()
                .unwrap()
                .contains("lettuce")
        );
    }
}

#[test]
fn an_unknown_setting_is_a_clear_error() {
    let err = KinovaFeedingEnv::new(KinovaFeedingConfig {
        settings: vec!["bowl".into()],
        ..KinovaFeedingConfig::default()
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("settings") && err.contains("bowl"), "{err}");
}

#[test]
#[ignore = "e2e: needs MuJoCo physics; bash scripts/test runs it"]
fn calibration_does_not_depend_on_the_number_of_threads() {
    use hil_kinova_mujoco::{CalibrationOptions, calibrate_with};
    let run = |threads| {
        let opts = CalibrationOptions {
            foods: vec![FoodKind::Banana],
            trials: 3,
            threads,
            ..CalibrationOptions::default()
        };
        let mut log = Vec::new();
        let report = calibrate_with(&opts, &|_, _| {}, &mut |r| log.push(r.clone())).unwrap();
        (report.rows, log)
    };
    let (rows1, log1) = run(1);
    let (rows2, log2) = run(2);
    assert_eq!(rows1, rows2);
    assert_eq!(log1.len(), 18);
    for (a, b) in log1.iter().zip(&log2) {
        assert_eq!(
            (a.seed, a.setting, &a.report),
            (b.seed, b.setting, &b.report)
        );
    }
    // Trials cycle through the settings: one per setting here.
    assert!(
        rows1
            .iter()
            .all(|r| r.by_setting.iter().all(|c| c.counts.trials == 1))
    );
    assert_eq!(rows1[4].published, Some(0.57)); // TA0, setting `all`
}
