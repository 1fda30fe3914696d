//! Exact serialisation of a ChaCha8 generator: seed, stream and word position.

use hil_core::{HilError, Result};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::Value;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RngState {
    seed: String,
    stream: u64,
    /// u128 does not fit JSON numbers; kept as a decimal string.
    word_pos: String,
}

pub(super) fn save(rng: &ChaCha8Rng) -> Value {
    let seed: String = rng.get_seed().iter().map(|b| format!("{b:02x}")).collect();
    serde_json::to_value(RngState {
        seed,
        stream: rng.get_stream(),
        word_pos: rng.get_word_pos().to_string(),
    })
    .expect("plain data always serialises")
}

pub(super) fn restore(v: Value) -> Result<ChaCha8Rng> {
    let what = "linucb_exp_decay RNG state";
    let s: RngState = serde_json::from_value(v).map_err(|e| HilError::serde(what, e))?;
    if s.seed.len() != 64 || !s.seed.is_ascii() {
        return Err(HilError::serde(what, "seed must be 64 hex digits"));
    }
    let mut seed = [0u8; 32];
    for (i, b) in seed.iter_mut().enumerate() {
        *b = u8::from_str_radix(&s.seed[2 * i..2 * i + 2], 16)
            .map_err(|e| HilError::serde(what, format!("seed: {e}")))?;
    }
    let word_pos: u128 = s
        .word_pos
        .parse()
        .map_err(|e| HilError::serde(what, format!("word_pos `{}`: {e}", s.word_pos)))?;
    let mut rng = ChaCha8Rng::from_seed(seed);
    rng.set_stream(s.stream);
    rng.set_word_pos(word_pos);
    Ok(rng)
}
