//! One LinUCB step (score every arm + update one) of the kernel-form
//! estimator at d = 2048, 6 arms, 300 pretraining rows per arm, in the two
//! regimes the row store's product memo must serve:
//!
//! - `fresh`: a new context every step, as a live robot sees
//!   (`hil bench policy` measures this regime against the bandwidth floor);
//! - `repeated`: a few contexts over and over, as replayed datasets present
//!   them in every episode of `hil reproduce`.
//!
//! Synthetic contexts (seeded). Only the public estimator API is used, so
//! `scripts/bench-compare` can run this file unchanged at an older commit:
//! `cargo bench -p hil-policies --bench contexts`.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use hil_core::{ArmId, Context, LabelledObservation};
use hil_policies::{EstimatorOptions, LinearArms, RepresentationChoice};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DIM: usize = 2048;
const ARMS: usize = 6;
const PER_ARM: usize = 300;
/// Distinct contexts of the repeated regime (a replayed dataset's items).
const REPEATED: usize = 16;

fn ctx(rng: &mut ChaCha8Rng) -> Context {
    let s = (3.0 / DIM as f64).sqrt();
    Context::new(
        (0..DIM)
            .map(|_| rng.random_range(-s..s))
            .collect::<Vec<_>>(),
    )
    .unwrap()
}

/// A kernel-form estimator pretrained on a fresh context per arm and row.
fn pretrained() -> LinearArms {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let data: Vec<_> = (0..PER_ARM * ARMS)
        .map(|i| LabelledObservation {
            context: ctx(&mut rng),
            arm: ArmId(i % ARMS),
            reward: f64::from(rng.random_bool(0.5)),
        })
        .collect();
    let opts = EstimatorOptions {
        representation: RepresentationChoice::Kernel,
        ..Default::default()
    };
    let mut e = LinearArms::with_options(ARMS, DIM, 1.0, opts).unwrap();
    e.pretrain(&data).unwrap();
    e
}

fn step(e: &mut LinearArms, x: &Context, arm: usize) {
    let s = e.scores(x).unwrap();
    e.update(x, ArmId(arm % ARMS), s[0].estimate).unwrap();
}

fn benches(c: &mut Criterion) {
    let base = pretrained();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut group = c.benchmark_group("step_d2048_6arms_300each");
    group.bench_function("fresh", |b| {
        let mut k = 0;
        b.iter_batched_ref(
            || {
                k += 1;
                (base.clone(), ctx(&mut rng), k)
            },
            |(e, x, k)| step(e, x, *k),
            BatchSize::LargeInput,
        )
    });
    let pool: Vec<Context> = (0..REPEATED).map(|_| ctx(&mut rng)).collect();
    // Every context seen before the clock starts, as after reproduce's
    // first episodes.
    for x in &pool {
        base.clone().scores(x).unwrap();
    }
    group.bench_function("repeated", |b| {
        let mut k = 0;
        b.iter_batched_ref(
            || {
                k += 1;
                (base.clone(), pool[k % REPEATED].clone(), k)
            },
            |(e, x, k)| step(e, x, *k),
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group! {
    name = contexts;
    config = Criterion::default().sample_size(30);
    targets = benches
}
criterion_main!(contexts);
