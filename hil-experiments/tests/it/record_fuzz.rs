//! Property test of the log reader and of resuming: a valid log, mutated
//! (truncated, bits flipped, lines spliced from another log, removed or
//! repeated, numbers made huge, junk inserted), is either resumed or
//! refused with an error naming the file (and the line, where one is at
//! fault); never a panic.
//!
//! Bounded: a few hundred cases on logs of about a hundred lines, well
//! under a few seconds in a debug build.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use proptest::prelude::*;

use hil_conformance::fixtures::{CountingWorkload, ScriptedPolicy, TableEnv};
use hil_core::channel::PerfectExpert;
use hil_core::{ActionSpace, ArmId, Choice, HilError, QueryKind, SessionSettings};
use hil_experiments::Experiment;
use hil_experiments::run_recorded;
use hil_record::{Header, RecordLog};

fn dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // tmpfs where available: every case writes and fsyncs a log.
        let shm = Path::new("/dev/shm");
        let base = if shm.is_dir() {
            shm.to_path_buf()
        } else {
            std::env::temp_dir()
        };
        let d = base.join(format!("hil-record-fuzz-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    })
}

fn experiment(seed: u64) -> Experiment {
    let env = TableEnv::new(
        ActionSpace::new(["A", "B", "C"]).unwrap(),
        vec![
            ("kiwi", vec![0.2, 0.7, 0.4]),
            ("pea", vec![0.5, 0.1, 0.3]),
            ("kiwi", vec![0.2, 0.7, 0.4]),
        ],
    )
    .unwrap();
    let q = Choice::Query {
        kind: QueryKind::default(),
        fallback: ArmId(0),
    };
    Experiment {
        settings: SessionSettings::default().with_n_att(3),
        seed,
        episodes: 3,
        environment: Box::new(env),
        policy: Box::new(ScriptedPolicy::new(
            3,
            4,
            vec![
                q,
                Choice::Act { arm: ArmId(1) },
                Choice::Act { arm: ArmId(2) },
            ],
        )),
        channel: Box::new(PerfectExpert::default()),
        workload: Arc::new(CountingWorkload::new(0.05)),
        forecast: None,
    }
}

fn header(seed: u64) -> Header {
    Header::new(&format!("seed = {seed}\n"), "exp.toml", ".", seed, 3)
}

/// The bytes of a complete recorded session with `seed`.
fn recorded(seed: u64) -> Vec<u8> {
    let path = dir().join(format!("reference-{seed}.jsonl"));
    let _ = std::fs::remove_file(&path);
    let log = RecordLog::create(&path, header(seed)).unwrap();
    run_recorded(&mut experiment(seed), log, None, &mut [], |_, _| {}).unwrap();
    std::fs::read(&path).unwrap()
}

fn logs() -> &'static (Vec<u8>, Vec<u8>) {
    static LOGS: OnceLock<(Vec<u8>, Vec<u8>)> = OnceLock::new();
    LOGS.get_or_init(|| (recorded(42), recorded(7)))
}

#[derive(Clone, Debug)]
enum Mutation {
    Truncate(prop::sample::Index),
    FlipBit(prop::sample::Index, u8),
    /// Replaces a line with a line of the other log.
    Splice(prop::sample::Index, prop::sample::Index),
    RemoveLine(prop::sample::Index),
    RepeatLine(prop::sample::Index),
    /// Replaces a run of digits with an extreme number.
    HugeNumber(prop::sample::Index, &'static str),
    Junk(prop::sample::Index, Vec<u8>),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let index = any::<prop::sample::Index>;
    prop_oneof![
        index().prop_map(Mutation::Truncate),
        (index(), 0u8..8).prop_map(|(i, b)| Mutation::FlipBit(i, b)),
        (index(), index()).prop_map(|(a, b)| Mutation::Splice(a, b)),
        index().prop_map(Mutation::RemoveLine),
        index().prop_map(Mutation::RepeatLine),
        (
            index(),
            prop::sample::select(vec![
                "1e400",
                "-1",
                "18446744073709551616",
                "99999999999999999999999999999999",
                "1.7976931348623157e308",
                "NaN",
                "0.0000000000000000000000000001",
            ])
        )
            .prop_map(|(i, n)| Mutation::HugeNumber(i, n)),
        (index(), prop::collection::vec(any::<u8>(), 1..48))
            .prop_map(|(i, j)| Mutation::Junk(i, j)),
    ]
}

fn lines(bytes: &[u8]) -> Vec<Vec<u8>> {
    bytes
        .split_inclusive(|b| *b == b'\n')
        .map(<[u8]>::to_vec)
        .collect()
}

fn apply(mut bytes: Vec<u8>, m: &Mutation, other: &[u8]) -> Vec<u8> {
    if bytes.is_empty() {
        return bytes;
    }
    match m {
        Mutation::Truncate(i) => bytes.truncate(i.index(bytes.len())),
        Mutation::FlipBit(i, b) => {
            let at = i.index(bytes.len());
            bytes[at] ^= 1 << b;
        }
        Mutation::Splice(a, b) => {
            let mut ls = lines(&bytes);
            let theirs = lines(other);
            let at = a.index(ls.len());
            ls[at] = theirs[b.index(theirs.len())].clone();
            bytes = ls.concat();
        }
        Mutation::RemoveLine(i) => {
            let mut ls = lines(&bytes);
            ls.remove(i.index(ls.len()));
            bytes = ls.concat();
        }
        Mutation::RepeatLine(i) => {
            let mut ls = lines(&bytes);
            let at = i.index(ls.len());
            let l = ls[at].clone();
            ls.insert(at, l);
            bytes = ls.concat();
        }
        Mutation::HugeNumber(i, n) => {
            let digits: Vec<usize> = (0..bytes.len())
                .filter(|&k| {
                    bytes[k].is_ascii_digit() && (k == 0 || !bytes[k - 1].is_ascii_digit())
                })
                .collect();
            if !digits.is_empty() {
                let start = digits[i.index(digits.len())];
                let end = (start..bytes.len())
                    .find(|&k| !bytes[k].is_ascii_digit())
                    .unwrap_or(bytes.len());
                bytes.splice(start..end, n.bytes());
            }
        }
        Mutation::Junk(i, junk) => {
            let at = i.index(bytes.len() + 1);
            bytes.splice(at..at, junk.iter().copied());
        }
    }
    bytes
}

/// The error names `path`, and a line between 1 and `max_line` if any.
fn assert_names_the_file(e: &HilError, path: &Path, max_line: usize) {
    match e {
        HilError::Io { path: p, .. } => assert_eq!(p, path, "{e}"),
        HilError::Data {
            path: p, record, ..
        } => {
            assert_eq!(p, path, "{e}");
            assert!(
                (1..=max_line).contains(record),
                "line {record} of {max_line}: {e}"
            );
        }
        other => panic!("an error that does not name the log: {other:?}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn mutated_logs_resume_or_are_refused_naming_file_and_line(
        mutations in prop::collection::vec(mutation(), 1..4),
        use_other in any::<bool>(),
    ) {
        let (ours, theirs) = logs();
        let (base, other) = if use_other { (theirs, ours) } else { (ours, theirs) };
        let mut bytes = base.clone();
        for m in &mutations {
            bytes = apply(bytes, m, other);
        }
        let path = dir().join("case.jsonl");
        std::fs::write(&path, &bytes).unwrap();
        let max_line = bytes.iter().filter(|b| **b == b'\n').count() + 1;
        match RecordLog::open(&path) {
            Err(e) => assert_names_the_file(&e, &path, max_line),
            Ok((log, logged)) => {
                let seed = logged.header.seed;
                let result = run_recorded(&mut experiment(seed), log, Some(&logged), &mut [], |_, _| {});
                if let Err(e) = result {
                    assert_names_the_file(&e, &path, max_line);
                }
            }
        }
    }
}
