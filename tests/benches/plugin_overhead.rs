//! What crossing the plugin boundary costs: the same policy called directly,
//! through the panic guard in-process, and loaded from a shared library.
//!
//! `cargo bench -p hil-integration-tests --bench plugin_overhead`

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use hil_config::BuildContext;
use hil_config::TaskContext;
use hil_conformance::cdylib::{build_cdylibs, cdylib_path};
use hil_conformance::fixtures::ScriptedPolicy;
use hil_core::{
    ActionSpace, ArmId, Choice, Context, DecisionInput, Policy, QueryHistory, WorkloadForecast,
};
use hil_plugin::{self as plugin, Params};

fn input_for<'a>(x: &'a Context, h: &'a QueryHistory) -> DecisionInput<'a> {
    DecisionInput::new(x, 1, WorkloadForecast::none(h)).at_item(0, 0, 1)
}

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let dir = build_cdylibs(root, &["hil-example-policy-thompson"]).unwrap();
    plugin::load(&cdylib_path(&dir, "hil-example-policy-thompson")).unwrap();
    plugin::register_static(Path::new("bench-static"), |r| {
        r.policy("bench_scripted", "", |_, _| {
            Ok(Box::new(ScriptedPolicy::new(
                6,
                32,
                vec![Choice::Act { arm: ArmId(2) }],
            )))
        });
    })
    .unwrap();

    let dim = 32;
    let x = Context::new(
        (0..dim)
            .map(|i| (i as f64 * 0.37).sin())
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let h = QueryHistory::new();
    let ctx = TaskContext::new(
        BuildContext::new(".", 3),
        ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap(),
        dim,
    );

    let mut g = c.benchmark_group("decide, trivial policy (d = 32)");
    let mut direct = ScriptedPolicy::new(6, dim, vec![Choice::Act { arm: ArmId(2) }]);
    g.bench_function("direct", |b| {
        b.iter(|| direct.decide(&input_for(&x, &h)).unwrap())
    });
    let mut guarded = plugin::build_policy("bench_scripted", &Params::empty(), &ctx).unwrap();
    g.bench_function("panic guard", |b| {
        b.iter(|| guarded.decide(&input_for(&x, &h)).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("decide, linear Thompson (6 arms, d = 32)");
    let params = Params::empty();
    let mut stat = hil_example_policy_thompson::build(&params, &ctx).unwrap();
    g.bench_function("static", |b| {
        b.iter(|| stat.decide(&input_for(&x, &h)).unwrap())
    });
    let mut dynamic = plugin::build_policy("linear_thompson", &params, &ctx).unwrap();
    g.bench_function("plugin", |b| {
        b.iter(|| dynamic.decide(&input_for(&x, &h)).unwrap())
    });
    g.finish();

    c.bench_function("load an already loaded plugin", |b| {
        let p = cdylib_path(&dir, "hil-example-policy-thompson");
        b.iter(|| plugin::load(&p).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
