//! The interaction record's costs: one recorded step (a `step` line and an
//! `outcome` line, each written and fsync'ed), and reading a long log back
//! when resuming (parsing and verifying every line's place in the hash
//! chain).
//!
//! The log lives under `target/` (a real disk, not tmpfs), so the step cost
//! is dominated by the disk's fsync latency.

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use hil_core::{ArmId, Context, Outcome, PendingStep, SessionObserver, StepDecision, StepEvent};
use hil_record::chain::Chain;
use hil_record::{Header, Record, RecordLog, Recorder};

fn dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../target/bench-record")
        .join(std::process::id().to_string());
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn step(t: u64) -> StepEvent {
    StepEvent {
        step: PendingStep {
            t,
            item_index: 0,
            item_label: "banana".into(),
            attempt: 0,
            context: Context::new(vec![0.25; 16]).unwrap(),
            decision: StepDecision::Act { arm: ArmId(2) },
            diagnostics: None,
            response: None,
            arm: ArmId(2),
            wl_t: 0.5,
        },
        outcome: Outcome::new(true).with_success_probability(0.7),
    }
}

fn bench(c: &mut Criterion) {
    let d = dir();
    let path = d.join("append.jsonl");
    let _ = std::fs::remove_file(&path);
    let mut rec = Recorder::new(RecordLog::create(&path, Header::new("", "x", ".", 0, 1)).unwrap());
    let mut t = 0;
    c.bench_function("record one step (2 lines, 2 fsyncs)", |b| {
        b.iter(|| {
            t += 1;
            let e = step(t);
            rec.before_execute(&e.step).unwrap();
            rec.on_step(&e).unwrap();
        })
    });

    // The long log is written directly (no fsync per line), so that
    // `cargo test --all-targets`, which runs this once, stays fast; each
    // line is chained as a log's writer chains it.
    let long = d.join("long.jsonl");
    let mut chain = Chain::start();
    let mut text = String::new();
    let mut push = |r: &Record| {
        text.push_str(&chain.seal(&serde_json::to_string(r).unwrap(), true));
        text.push('\n');
    };
    push(&Record::Header(Header::new("", "x", ".", 0, 1)));
    for t in 1..=5000 {
        let e = step(t);
        let lines = [
            Record::Step {
                episode: 0,
                step: e.step.clone(),
            },
            Record::Outcome {
                episode: 0,
                t,
                outcome: e.outcome,
            },
        ];
        for r in &lines {
            push(r);
        }
    }
    std::fs::write(&long, text).unwrap();
    c.bench_function("open a 10 001-line log for resuming", |b| {
        b.iter(|| RecordLog::open(&long).unwrap().1.records.len())
    });
    let _ = std::fs::remove_dir_all(&d);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
