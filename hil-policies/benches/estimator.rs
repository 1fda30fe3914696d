//! Criterion benches of one LinUCB step (score every arm + update one) in
//! both representations. `hil bench policy` reports the same quantity with
//! the bandwidth floor beside it. Synthetic contexts.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use hil_core::{ArmId, Context, LabelledObservation};
use hil_policies::{EstimatorOptions, LinearArms, RepresentationChoice};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn ctx(rng: &mut ChaCha8Rng, d: usize) -> Context {
    let s = (3.0 / d as f64).sqrt();
    Context::new((0..d).map(|_| rng.random_range(-s..s)).collect::<Vec<_>>()).unwrap()
}

fn fitted(d: usize, arms: usize, per_arm: usize, r: RepresentationChoice) -> LinearArms {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let data: Vec<_> = (0..per_arm * arms)
        .map(|i| LabelledObservation {
            context: ctx(&mut rng, d),
            arm: ArmId(i % arms),
            reward: f64::from(rng.random_bool(0.5)),
        })
        .collect();
    let opts = EstimatorOptions {
        representation: r,
        ..Default::default()
    };
    let mut e = LinearArms::with_options(arms, d, 1.0, opts).unwrap();
    e.pretrain(&data).unwrap();
    e
}

fn step(
    c: &mut Criterion,
    name: &str,
    d: usize,
    arms: usize,
    per_arm: usize,
    r: RepresentationChoice,
) {
    let base = fitted(d, arms, per_arm, r);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let x = ctx(&mut rng, d);
    c.bench_function(name, |b| {
        b.iter_batched_ref(
            || base.clone(),
            |e| {
                let s = e.scores(&x).unwrap();
                e.update(&x, ArmId(0), s[0].estimate).unwrap();
            },
            BatchSize::LargeInput,
        )
    });
}

fn benches(c: &mut Criterion) {
    step(
        c,
        "kernel_d2048_6arms_300each",
        2048,
        6,
        300,
        RepresentationChoice::Kernel,
    );
    step(
        c,
        "dense_d1024_6arms_1000each",
        1024,
        6,
        1000,
        RepresentationChoice::Dense,
    );
}

criterion_group! {
    name = estimator;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(estimator);
