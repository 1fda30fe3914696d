//! # hil-speech
//!
//! Spoken queries for **hil**, offline: [`SpeechChannel`] says a query and
//! its choices (espeak-ng), hears the answer from a microphone (arecord)
//! or a file, and decodes it with pocketsphinx restricted to the query's
//! [`grammar`]; `[channel] type = "speech"` ([`SpeechChannelConfig`]) builds
//! it from a config. The engines are Debian packages installed by
//! `scripts/setup-speech` and linked only with the `engines` feature; the
//! grammar, audio handling and config build without them. See README.md.

pub mod audio;
#[cfg(feature = "engines")]
pub mod bench;
pub mod channel;
pub mod denoise;
pub mod endpoint;
pub mod grammar;
pub mod listen;
pub mod listener;
pub mod recognize;
pub mod source;
#[cfg(feature = "engines")]
pub mod sphinx;
pub mod stop;
#[cfg(test)]
mod test_signals;
pub mod tts;

pub use channel::{SpeechChannel, SpeechSettings};
pub mod config;
pub use config::SpeechChannelConfig;
