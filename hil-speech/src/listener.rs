//! A scripted person who answers aloud: it decides what to say from the
//! query, espeak-ng says it into a WAV file, and the channel hears that
//! file through the same path as a microphone's audio. The end-to-end
//! tests and `hil bench speech` answer with it.

use std::path::PathBuf;

use hil_core::{Query, Result};

use crate::audio::{Audio, RECOGNIZER_RATE};
use crate::source::{AudioSource, AudioStream, MemoryStream};
use crate::tts::EspeakVoice;

/// Decides what the listener says to a query on an attempt (`None`: it
/// stays silent).
pub type Script = Box<dyn FnMut(&Query, usize) -> Option<String> + Send>;

/// Silence before and after the answer, in seconds: a person does not
/// start on the prompt's last sample, and the detector needs the hangover.
pub const LEAD_S: f64 = 0.4;
/// Silence after the answer, in seconds.
pub const TAIL_S: f64 = 0.8;

/// The audio of a phrase as a listener says it: `LEAD_S` of silence, the
/// phrase in `voice` (espeak-ng's own rate), `TAIL_S` of silence.
pub fn say(voice: &EspeakVoice, phrase: &str, scratch: &std::path::Path) -> Result<Audio> {
    let speech = voice.synthesize(phrase, scratch)?;
    let rate = speech.rate;
    let pad = |s: f64| vec![0.0f32; (s * f64::from(rate)) as usize];
    let mut samples = pad(LEAD_S);
    samples.extend_from_slice(&speech.samples);
    samples.extend(pad(TAIL_S));
    Ok(Audio { rate, samples })
}

/// A listener that speaks its script's answers.
pub struct ScriptedListener {
    voice: EspeakVoice,
    script: Script,
    scratch: PathBuf,
    /// Every phrase it said, in order.
    pub said: Vec<String>,
}

impl std::fmt::Debug for ScriptedListener {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScriptedListener")
            .field("voice", &self.voice)
            .field("said", &self.said)
            .finish_non_exhaustive()
    }
}

impl ScriptedListener {
    /// A listener speaking in `voice`, making its WAV files in `scratch`.
    pub fn new(voice: EspeakVoice, scratch: PathBuf, script: Script) -> Self {
        Self {
            voice,
            script,
            scratch,
            said: Vec::new(),
        }
    }
}

impl AudioSource for ScriptedListener {
    fn open(&mut self, query: &Query, attempt: usize) -> Result<Box<dyn AudioStream>> {
        let audio = match (self.script)(query, attempt) {
            Some(phrase) => {
                let a = say(&self.voice, &phrase, &self.scratch)?;
                self.said.push(phrase);
                a
            }
            None => Audio {
                rate: RECOGNIZER_RATE,
                samples: vec![0.0; RECOGNIZER_RATE as usize * 2],
            },
        };
        Ok(Box::new(MemoryStream::new(audio)))
    }
}
