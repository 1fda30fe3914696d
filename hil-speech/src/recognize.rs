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
    /// How sure the recognizer is, in [0, 1] (pocketsphinx: the best
    /// path's posterior among the grammar's alternatives).
    pub confidence: f64,
}

/// Decodes utterances (16 kHz, 16-bit) restricted to a query's grammar.
pub trait Recognizer: Send + std::fmt::Debug {
    /// Decodes `samples` in `grammar`.
    fn recognize(&mut self, grammar: &Grammar, samples: &[i16]) -> Result<Recognition>;
}

#[cfg(feature = "engines")]
pub use engine::SphinxRecognizer;

#[cfg(feature = "engines")]
mod engine {
    use super::*;
    use crate::sphinx::{ModelFiles, Sphinx};

    /// pocketsphinx restricted to the query's grammar.
    #[derive(Debug)]
    pub struct SphinxRecognizer {
        sphinx: Sphinx,
    }

    impl SphinxRecognizer {
        /// Loads the model in `model_dir` (Debian's layout).
        pub fn new(model_dir: &std::path::Path) -> Result<Self> {
            Ok(Self {
                sphinx: Sphinx::new(&ModelFiles::in_dir(model_dir)?)?,
            })
        }

        /// The raw decoding (the bench reads the ratio).
        pub fn decode(
            &mut self,
            grammar: &Grammar,
            samples: &[i16],
        ) -> Result<crate::sphinx::Decoded> {
            self.sphinx.set_grammar(&grammar.jsgf())?;
            self.sphinx.decode(samples)
        }
    }

    impl Recognizer for SphinxRecognizer {
        fn recognize(&mut self, grammar: &Grammar, samples: &[i16]) -> Result<Recognition> {
            let d = self.decode(grammar, samples)?;
            let meaning = grammar.meaning(&d.hypothesis);
            let confidence = if meaning.is_some() { d.posterior } else { 0.0 };
            Ok(Recognition {
                transcript: d.hypothesis,
                meaning,
                confidence,
            })
        }
    }
}
