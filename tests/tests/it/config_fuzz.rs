//! A property-test fuzz target for the experiment TOML loader
//! (`ExperimentConfig::parse`): valid configs mutated by truncation, bit
//! flips, huge and non-finite numbers, deep nesting and junk bytes are
//! either accepted or refused with an error naming the file; nothing
//! panics or aborts, and no message grows with the input (issue 14).
//!
//! Bounded: a fixed number of cases, well under a few seconds in a debug
//! build.

use std::path::Path;

use hil_core::error::ECHO_CHARS;
use hil_experiments::ExperimentConfig;
use proptest::prelude::*;

// Linked so that their component types are registered.
use hil_channels as _;
use hil_envs as _;
use hil_policies as _;
use hil_workload as _;

/// Valid configs covering every built-in component kind the loader reads
/// without I/O.
const SEEDS: [&str; 2] = [
    r#"seed = 3
episodes = 2

[session]
n_att = 3
wl0 = 0.5
max_items = 8

[environment]
type = "demo_plate"
foods = ["banana", "grape"]
repeat = 2

[policy]
type = "demo_learner"
query_probability = 0.5
epsilon = 0.1
kinds = [{ response = "mcq" }, { response = "bounding_box", difficulty = "hard" }]

[workload]
type = "demo_counting"
increment = 0.05
window = 10

[channel]
type = "simulated_expert"
error_rate = 0.1
response_time = { median_s = 4.0, sigma = 0.5 }
"#,
    r#"seed = 1
episodes = 3

[environment]
type = "food_replay"
foods = ["banana", "carrot"]
items_per_episode = 5

[policy]
type = "linucb_qg"
alpha = 0.5
lambda = 1.0
w = 0.2
query_kind = { response = "mcq" }
[policy.estimator]
representation = "auto"
crossover = 0.4

[workload]
type = "bundled"
name = "f1_sim"

[policy_workload]
type = "demo_counting"
increment = 0.1
window = 5

[channel]
type = "simulated_expert"
"#,
];

/// Numbers that break naive loaders.
const NUMBERS: [&str; 14] = [
    "inf",
    "-inf",
    "nan",
    "1e308",
    "-1e308",
    "5e-324",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "99999999999999999999999",
    "4294967296",
    "1e12",
    "-1",
    "0",
];

#[derive(Clone, Debug)]
enum Mutation {
    /// Keep the first `at` bytes (mod the length).
    Truncate(usize),
    /// Flip bit `bit` of byte `at` (mod the length).
    FlipBit(usize, u8),
    /// Replace the `nth` number (mod the count) with one of [`NUMBERS`].
    Number(usize, usize),
    /// Insert `depth` nested arrays or inline tables as a value.
    Nest {
        depth: usize,
        tables: bool,
        at: usize,
    },
    /// Insert junk bytes at `at`.
    Junk(usize, Vec<u8>),
    /// Repeat a slice of the text many times (a long value or key).
    Long(usize, usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), 0u8..8).prop_map(|(a, b)| Mutation::FlipBit(a, b)),
        (any::<usize>(), 0..NUMBERS.len()).prop_map(|(n, v)| Mutation::Number(n, v)),
        (1usize..3000, any::<bool>(), any::<usize>())
            .prop_map(|(depth, tables, at)| Mutation::Nest { depth, tables, at }),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..32))
            .prop_map(|(a, j)| Mutation::Junk(a, j)),
        (any::<usize>(), 1usize..16, 1usize..20_000).prop_map(|(a, l, n)| Mutation::Long(a, l, n)),
    ]
}

/// Byte offsets at which a TOML number starts.
fn number_starts(text: &[u8]) -> Vec<usize> {
    (0..text.len())
        .filter(|&i| {
            let prev_ok = i == 0 || matches!(text[i - 1], b' ' | b'=' | b'[' | b',');
            prev_ok && (text[i].is_ascii_digit() || text[i] == b'-')
        })
        .collect()
}

fn apply(text: &mut Vec<u8>, m: &Mutation) {
    let at = |a: usize, text: &Vec<u8>| {
        if text.is_empty() {
            0
        } else {
            a % (text.len() + 1)
        }
    };
    match m {
        Mutation::Truncate(a) => {
            let cut = at(*a, text);
            text.truncate(cut);
        }
        Mutation::FlipBit(a, bit) => {
            if !text.is_empty() {
                let i = a % text.len();
                text[i] ^= 1 << bit;
            }
        }
        Mutation::Number(n, v) => {
            let starts = number_starts(text);
            if starts.is_empty() {
                return;
            }
            let s = starts[n % starts.len()];
            let end = (s..text.len())
                .find(|&i| !matches!(text[i], b'0'..=b'9' | b'.' | b'-' | b'e' | b'_'))
                .unwrap_or(text.len());
            text.splice(s..end, NUMBERS[*v].bytes());
        }
        Mutation::Nest {
            depth,
            tables,
            at: a,
        } => {
            let (open, close) = if *tables {
                ("{ a = ", " }")
            } else {
                ("[", "]")
            };
            let value = format!(
                "\nnest = {}1{}\n",
                open.repeat(*depth),
                close.repeat(*depth)
            );
            let i = at(*a, text);
            text.splice(i..i, value.bytes());
        }
        Mutation::Junk(a, junk) => {
            let i = at(*a, text);
            text.splice(i..i, junk.iter().copied());
        }
        Mutation::Long(a, len, n) => {
            if text.is_empty() {
                return;
            }
            let i = a % text.len();
            let slice: Vec<u8> = text[i..(i + len).min(text.len())].to_vec();
            let long = slice.repeat(*n);
            text.splice(i..i, long);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_configs_are_accepted_or_refused_with_the_file_named(
        seed in 0..SEEDS.len(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let mut bytes = SEEDS[seed].as_bytes().to_vec();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        let text = String::from_utf8_lossy(&bytes);
        let path = Path::new("fuzz/experiment.toml");
        if let Err(e) = ExperimentConfig::parse(&text, path) {
            prop_assert_eq!(&e.path, path);
            prop_assert!(e.to_string().starts_with("fuzz/experiment.toml:"), "{}", e);
            // Echoed values are shortened: the message does not grow with
            // the input.
            prop_assert!(e.to_string().len() < 16 * ECHO_CHARS, "{} bytes: {}", e.to_string().len(), e);
        }
    }
}

#[test]
fn the_seeds_are_valid() {
    for text in SEEDS {
        ExperimentConfig::parse(text, Path::new("seed.toml")).unwrap();
    }
}

#[test]
fn every_number_replacement_is_handled() {
    // Each special number in each numeric position, exhaustively.
    for text in SEEDS {
        for n in 0..number_starts(text.as_bytes()).len() {
            for v in 0..NUMBERS.len() {
                let mut bytes = text.as_bytes().to_vec();
                apply(&mut bytes, &Mutation::Number(n, v));
                let text = String::from_utf8(bytes).unwrap();
                if let Err(e) = ExperimentConfig::parse(&text, Path::new("n.toml")) {
                    assert_eq!(e.path, Path::new("n.toml"));
                    assert!(e.line > 0, "{e}\n{text}");
                }
            }
        }
    }
}

#[test]
fn very_deep_nesting_is_refused_without_overflowing_the_stack() {
    for (open, close) in [("[", "]"), ("{ a = ", " }")] {
        let depth = 1_000_000;
        let text = format!(
            "{}\nnest = {}1{}\n",
            SEEDS[0],
            open.repeat(depth),
            close.repeat(depth)
        );
        let e = ExperimentConfig::parse(&text, Path::new("deep.toml")).unwrap_err();
        assert_eq!(e.path, Path::new("deep.toml"));
    }
}
