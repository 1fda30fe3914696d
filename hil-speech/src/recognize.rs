//! From an utterance to a meaning: the [`Recognizer`] trait, and the
//! pocketsphinx one (feature `engines`).

use hil_core::Result;

use crate::grammar::{Grammar, Meaning};

/// Where Debian's `pocketsphinx-en-us` puts the US English model.
pub const DEFAULT_MODEL_DIR: &str = "/usr/share/pocketsphinx/model/en-us";

/// What the recognizer made of an utterance.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Recognition {
    /// The words recognized (the grammar's phrase; empty when none fit).
    pub transcript: String,
    /// What they mean in the query's grammar.
    pub meaning: Option<Meaning>,
    /// How sure the recognizer is, in [0, 1] (pocketsphinx: from the
    /// agreement of two decodings and their margin over the best answer
    /// of another meaning; see `SphinxRecognizer`).
    pub confidence: f64,
}

/// Decodes utterances (16 kHz, 16-bit) restricted to a query's grammar.
pub trait Recognizer: Send + std::fmt::Debug {
    /// Decodes `samples` in `grammar`.
    fn recognize(&mut self, grammar: &Grammar, samples: &[i16]) -> Result<Recognition>;
}

#[cfg(feature = "engines")]
pub use engine::{HALF_CONFIDENCE_MARGIN, NOISE_FLOOR_DBFS, SphinxRecognizer, Weighed};

#[cfg(feature = "engines")]
mod engine {
    use super::*;
    use crate::sphinx::{Decoded, ModelFiles, Sphinx};

    /// A steady noise floor added to every utterance before decoding, in dB
    /// full scale. Digital silence (a file, a muted gap) has no energy at
    /// all; pocketsphinx's front end takes the log of it, which throws its
    /// normalisation off: clean synthetic speech was recognized worse than
    /// the same speech at 20 dB SNR (on the tuning corpus of
    /// `examples/speech_tune.rs`, e.g. "six" as "three"); with this floor
    /// it is not. A real microphone's own noise is far above it.
    pub const NOISE_FLOOR_DBFS: f64 = -50.0;

    /// The rival margin, in pocketsphinx's score units (log base 1.0001)
    /// per 10 ms frame, at which the confidence is one half: chosen on the
    /// tuning corpus of `examples/speech_tune.rs` (voices, rates and noise
    /// `hil bench speech` does not use), as the margin above which wrong
    /// answers at 10 dB SNR became rare without asking again most of the
    /// time (`hil bench speech` reports how that holds on its corpus).
    pub const HALF_CONFIDENCE_MARGIN: f64 = 3.0;

    /// How the recognizer weighed one utterance (what the confidence is
    /// made of; `examples/speech_tune.rs` prints it).
    #[derive(Clone, Debug, PartialEq)]
    pub struct Weighed {
        /// The whole-utterance decoding's words.
        pub transcript: String,
        /// Their meaning, if in the grammar.
        pub meaning: Option<Meaning>,
        /// Whether the live decoding means the same.
        pub agree: bool,
        /// The smaller of the two decodings' margins over the best answer
        /// with a different meaning, in score units per frame (infinite
        /// when the grammar has no other meaning).
        pub margin: f64,
    }

    impl Weighed {
        /// The confidence in [0, 1]: 0 without a meaning or without
        /// agreement, else `1 - 2^(-margin / HALF_CONFIDENCE_MARGIN)`.
        pub fn confidence(&self) -> f64 {
            if self.meaning.is_none() || !self.agree {
                return 0.0;
            }
            1.0 - (-self.margin / HALF_CONFIDENCE_MARGIN).exp2()
        }
    }

    /// pocketsphinx restricted to the query's grammar. Its own posterior is
    /// about 1.0 over a small grammar whether or not the answer is right,
    /// so the confidence is built from comparisons instead: the utterance
    /// is decoded live and as a whole utterance (the two must mean the
    /// same), and each is compared with the best answer of a *different*
    /// meaning (the grammar without the answer's phrases, decoded again).
    /// Four small decodings: about 15 ms each on one idle core.
    #[derive(Debug)]
    pub struct SphinxRecognizer {
        sphinx: Sphinx,
    }

    /// `samples` with [`NOISE_FLOOR_DBFS`] of uniform noise added (the
    /// same noise every time: a decoding is repeatable).
    fn with_floor(samples: &[i16]) -> Vec<i16> {
        let amp = 10f64.powf(NOISE_FLOOR_DBFS / 20.0) * 3f64.sqrt() * 32767.0;
        let mut x = 0x9E37_79B9u32;
        samples
            .iter()
            .map(|&s| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                let u = f64::from(x) / f64::from(u32::MAX) * 2.0 - 1.0;
                (f64::from(s) + amp * u).round().clamp(-32768.0, 32767.0) as i16
            })
            .collect()
    }

    impl SphinxRecognizer {
        /// Loads the model in `model_dir` (Debian's layout).
        pub fn new(model_dir: &std::path::Path) -> Result<Self> {
            Self::with_options(model_dir, &[])
        }

        /// Loads the model with extra pocketsphinx options (pairs such as
        /// `["-lw", "6.5"]`).
        pub fn with_options(model_dir: &std::path::Path, options: &[&str]) -> Result<Self> {
            Ok(Self {
                sphinx: Sphinx::new(&ModelFiles::in_dir(model_dir)?, options)?,
            })
        }

        fn decode(&mut self, grammar: &Grammar, samples: &[i16], whole: bool) -> Result<Decoded> {
            self.sphinx.set_grammar(&grammar.jsgf())?;
            self.sphinx.decode_as(samples, whole)
        }

        /// The margin of `best` over the best answer of another meaning.
        fn margin(
            &mut self,
            rivals: Option<&Grammar>,
            samples: &[i16],
            whole: bool,
            best: &Decoded,
        ) -> Result<f64> {
            let Some(rivals) = rivals else {
                return Ok(f64::INFINITY);
            };
            let rival = self.decode(rivals, samples, whole)?;
            if rival.hypothesis.is_empty() {
                return Ok(f64::INFINITY);
            }
            Ok(f64::from(best.score - rival.score) / best.frames.max(1) as f64)
        }

        /// Decodes `samples` every way the confidence needs.
        pub fn weigh(&mut self, grammar: &Grammar, samples: &[i16]) -> Result<Weighed> {
            let samples = with_floor(samples);
            // The whole-utterance decoding (normalised over the utterance
            // itself) says what was said; the live one, which starts from
            // the model's initial normalisation, must mean the same.
            let whole = self.decode(grammar, &samples, true)?;
            let meaning = grammar.meaning(&whole.hypothesis);
            let mut weighed = Weighed {
                transcript: whole.hypothesis.clone(),
                meaning,
                agree: false,
                margin: 0.0,
            };
            let Some(m) = meaning else {
                return Ok(weighed);
            };
            let live = self.decode(grammar, &samples, false)?;
            weighed.agree = grammar.meaning(&live.hypothesis) == Some(m);
            if !weighed.agree {
                return Ok(weighed);
            }
            let rivals = grammar.without(m);
            let a = self.margin(rivals.as_ref(), &samples, false, &live)?;
            let b = self.margin(rivals.as_ref(), &samples, true, &whole)?;
            weighed.margin = a.min(b);
            Ok(weighed)
        }
    }

    impl Recognizer for SphinxRecognizer {
        fn recognize(&mut self, grammar: &Grammar, samples: &[i16]) -> Result<Recognition> {
            let w = self.weigh(grammar, samples)?;
            Ok(Recognition {
                confidence: w.confidence(),
                transcript: w.transcript,
                meaning: w.meaning,
            })
        }
    }
}
