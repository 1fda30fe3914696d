//! Kernel, dense and naive (direct-inverse) representations agree to 1e-8
//! relative, through pretraining, online updates, crossovers, duplicates
//! and checkpoints.

use crate::estimator::reference::NaiveArms;
use crate::{EstimatorOptions, LinearArms, Representation, RepresentationChoice};
use hil_core::{ArmId, Context, LabelledObservation};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn ctx(rng: &mut ChaCha8Rng, d: usize) -> Context {
    Context::new(
        (0..d)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect::<Vec<_>>(),
    )
    .unwrap()
}

fn close(a: f64, b: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1e-3);
    assert!(
        (a - b).abs() <= 1e-8 * scale,
        "{what}: {a} vs {b} (rel {})",
        (a - b).abs() / scale
    );
}

fn options(r: RepresentationChoice) -> EstimatorOptions {
    EstimatorOptions {
        representation: r,
        crossover: 0.5,
    }
}

fn check_all(ests: &mut [LinearArms], naive: &NaiveArms, x: &Context, n_arms: usize) {
    for a in 0..n_arms {
        let want = naive.estimate(a, x).unwrap();
        for e in ests.iter_mut() {
            let got = e.scores(x).unwrap()[a];
            close(got.estimate, want.estimate, "estimate");
            close(got.bonus, want.bonus, "bonus");
            let one = e.estimate(ArmId(a), x).unwrap();
            close(one.estimate, want.estimate, "single-arm estimate");
            let theta = e.theta(ArmId(a)).unwrap();
            for (t, w) in theta.iter().zip(naive.theta(a).unwrap()) {
                close(*t, w, "theta");
            }
        }
    }
}

#[test]
fn representations_agree_with_direct_inverse() {
    let (d, n_arms, lambda) = (12, 3, 0.7);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut ests: Vec<LinearArms> = [
        RepresentationChoice::Kernel,
        RepresentationChoice::Dense,
        RepresentationChoice::Auto,
    ]
    .into_iter()
    .map(|r| LinearArms::with_options(n_arms, d, lambda, options(r)).unwrap())
    .collect();
    let mut naive = NaiveArms::new(n_arms, d, lambda);

    // Pretraining batch: arm 0 gets enough to start dense under Auto.
    let mut batch = Vec::new();
    for i in 0..14 {
        let arm = if i < 8 { 0 } else { i % n_arms };
        let o = LabelledObservation {
            context: ctx(&mut rng, d),
            arm: ArmId(arm),
            reward: rng.random_range(0.0..1.0),
        };
        naive.push(arm, &o.context, o.reward);
        batch.push(o);
    }
    for e in &mut ests {
        e.pretrain(&batch).unwrap();
    }
    assert_eq!(
        ests[2].representation(ArmId(0)).unwrap(),
        Representation::Dense
    );
    assert_eq!(
        ests[2].representation(ArmId(1)).unwrap(),
        Representation::Kernel
    );
    check_all(&mut ests, &naive, &ctx(&mut rng, d), n_arms);

    // Online updates, scored first (cached path) or not, crossing over on arm 1.
    for step in 0..30 {
        let x = ctx(&mut rng, d);
        let arm = [1, 1, 2, 0][step % 4];
        let r = f64::from(rng.random_bool(0.5));
        if step % 3 != 0 {
            for e in &mut ests {
                e.scores(&x).unwrap();
            }
        }
        for e in &mut ests {
            e.update(&x, ArmId(arm), r).unwrap();
        }
        naive.push(arm, &x, r);
        check_all(&mut ests, &naive, &ctx(&mut rng, d), n_arms);
    }
    assert_eq!(
        ests[2].representation(ArmId(1)).unwrap(),
        Representation::Dense
    );
    assert_eq!(
        ests[0].representation(ArmId(1)).unwrap(),
        Representation::Kernel
    );
}

#[test]
fn duplicate_and_collinear_contexts_stay_finite() {
    let (d, lambda) = (6, 1e-6);
    for r in [RepresentationChoice::Kernel, RepresentationChoice::Dense] {
        let mut e = LinearArms::with_options(2, d, lambda, options(r)).unwrap();
        let mut naive = NaiveArms::new(2, d, lambda);
        let base = [1.0, -2.0, 0.5, 0.0, 3.0, 1.0];
        for k in 0..40 {
            // Scaled copies of one direction, many exact duplicates.
            let s = [1.0, 2.0, -1.0, 1.0][k % 4];
            let x = Context::new(base.iter().map(|v| v * s).collect::<Vec<_>>()).unwrap();
            e.scores(&x).unwrap();
            e.update(&x, ArmId(0), (k % 2) as f64).unwrap();
            naive.push(0, &x, (k % 2) as f64);
        }
        let probe = Context::new(base.to_vec()).unwrap();
        let other = Context::new(vec![0.0, 0.0, 1.0, 1.0, 0.0, 0.0]).unwrap();
        for x in [&probe, &other] {
            for s in e.scores(x).unwrap() {
                assert!(s.estimate.is_finite() && s.bonus.is_finite() && s.bonus >= 0.0);
            }
        }
        // Along the observed direction the estimate is the mean-ish fit.
        let want = naive.estimate(0, &probe).unwrap();
        let got = e.scores(&probe).unwrap()[0];
        assert!(
            (got.estimate - want.estimate).abs() < 1e-6,
            "{r:?}: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn checkpoint_round_trip_is_bit_exact() {
    let (d, n_arms) = (9, 2);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut e =
        LinearArms::with_options(n_arms, d, 0.3, options(RepresentationChoice::Auto)).unwrap();
    let batch: Vec<_> = (0..6)
        .map(|i| LabelledObservation {
            context: ctx(&mut rng, d),
            arm: ArmId(i % 2),
            reward: rng.random_range(0.0..1.0),
        })
        .collect();
    e.pretrain(&batch).unwrap();
    for i in 0..8 {
        let x = ctx(&mut rng, d);
        e.scores(&x).unwrap();
        e.update(&x, ArmId(i % 2), 0.1 * i as f64).unwrap();
    }
    let text = serde_json::to_string(&e.save_state()).unwrap();
    let mut r = LinearArms::from_state(serde_json::from_str(&text).unwrap()).unwrap();
    for _ in 0..5 {
        let x = ctx(&mut rng, d);
        let a = e.scores(&x).unwrap();
        let b = r.scores(&x).unwrap();
        for (p, q) in a.iter().zip(&b) {
            assert_eq!(p.estimate.to_bits(), q.estimate.to_bits());
            assert_eq!(p.bonus.to_bits(), q.bonus.to_bits());
        }
        e.update(&x, ArmId(1), 1.0).unwrap();
        r.update(&x, ArmId(1), 1.0).unwrap();
    }
}

#[test]
fn bad_input_is_an_error_naming_the_value() {
    use hil_core::HilError;
    let parameter = |r: hil_core::Result<LinearArms>| match r.unwrap_err() {
        HilError::InvalidParameter { name, .. } => name,
        other => panic!("not an invalid parameter: {other:?}"),
    };
    assert_eq!(parameter(LinearArms::new(2, 3, 0.0)), "lambda");
    assert_eq!(parameter(LinearArms::new(2, 3, -1.0)), "lambda");
    assert_eq!(parameter(LinearArms::new(2, 3, f64::NAN)), "lambda");
    assert_eq!(parameter(LinearArms::new(0, 3, 1.0)), "n_arms");
    assert_eq!(parameter(LinearArms::new(1025, 3, 1.0)), "n_arms");
    assert_eq!(parameter(LinearArms::new(2, 0, 1.0)), "dim");
    assert_eq!(parameter(LinearArms::new(2, 8193, 1.0)), "dim");
    // A 20-digit dimension is refused before any allocation.
    assert_eq!(parameter(LinearArms::new(2, usize::MAX, 1.0)), "dim");
    assert!(LinearArms::new(1024, 8192, 1.0).is_ok());
    let bad = EstimatorOptions {
        crossover: 0.0,
        ..Default::default()
    };
    assert_eq!(
        parameter(LinearArms::with_options(2, 3, 1.0, bad)),
        "crossover"
    );

    let mut e = LinearArms::new(2, 3, 1.0).unwrap();
    let x = Context::new(vec![1.0, 2.0, 3.0]).unwrap();
    let r = e.scores(&[1.0, f64::INFINITY, 0.0]).unwrap_err();
    assert!(
        matches!(r, HilError::InvalidInput { ref what, ref why } if what == "context[1]" && why.contains("inf")),
        "{r:?}"
    );
    let r = e.scores(&[1.0, 2.0]).unwrap_err();
    assert!(
        matches!(
            r,
            HilError::DimensionMismatch {
                expected: 3,
                got: 2
            }
        ),
        "{r:?}"
    );
    let r = e.update(&x, ArmId(2), 1.0).unwrap_err();
    assert!(
        matches!(r, HilError::ArmOutOfRange { arm: 2, n_arms: 2 }),
        "{r:?}"
    );
    let r = e.update(&x, ArmId(0), f64::NAN).unwrap_err();
    assert!(
        matches!(r, HilError::InvalidInput { ref what, .. } | HilError::InvalidParameter { name: ref what, .. } if what == "reward"),
        "{r:?}"
    );
    let wrong = Context::new(vec![1.0; 4]).unwrap();
    let r = e
        .pretrain(&[
            LabelledObservation {
                context: x.clone(),
                arm: ArmId(0),
                reward: 1.0,
            },
            LabelledObservation {
                context: wrong,
                arm: ArmId(0),
                reward: 1.0,
            },
        ])
        .unwrap_err();
    // The record at fault (#1) is named with the mismatch.
    let msg = r.to_string();
    assert!(
        matches!(r, HilError::InvalidInput { .. })
            && msg.contains("record #1")
            && msg.contains("expected 3, got 4"),
        "{r:?}"
    );
    // Nothing was applied from the rejected batch.
    assert_eq!(e.n_observations(ArmId(0)).unwrap(), 0);
}
