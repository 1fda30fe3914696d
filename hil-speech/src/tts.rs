//! Text to speech with espeak-ng (its program, from Debian's `espeak-ng`):
//! a prompt becomes audio, which a [`Voice`] plays to a device or keeps.

use std::path::{Path, PathBuf};
use std::process::Command;

use hil_core::{HilError, Result};

use crate::audio::Audio;

/// How espeak-ng speaks: a voice name (`espeak-ng --voices=en` lists them,
/// e.g. `en-us`, `en-gb`, `en-us+f3`) and words per minute.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EspeakVoice {
    /// espeak-ng's voice.
    pub voice: String,
    /// Words per minute (espeak-ng takes 80–450).
    pub rate: u32,
}

impl Default for EspeakVoice {
    fn default() -> Self {
        Self {
            voice: "en-us".into(),
            rate: 160,
        }
    }
}

fn program_error(program: &str, e: std::io::Error) -> HilError {
    HilError::channel(
        "speech",
        format!("cannot run `{program}` ({e}): run scripts/setup-speech, which installs it"),
    )
}

impl EspeakVoice {
    /// Checks the rate.
    pub fn validate(&self) -> Result<()> {
        if !(80..=450).contains(&self.rate) {
            return Err(HilError::invalid_input(
                "rate",
                format!(
                    "espeak-ng speaks 80 to 450 words per minute, got {}",
                    self.rate
                ),
            ));
        }
        if self.voice.trim().is_empty() || self.voice.starts_with('-') {
            return Err(HilError::invalid_input(
                "voice",
                "name an espeak-ng voice, e.g. en-us",
            ));
        }
        Ok(())
    }

    /// Speaks `text` into a WAV file at `path` (espeak-ng's 22.05 kHz).
    pub fn synthesize_to(&self, text: &str, path: &Path) -> Result<()> {
        self.validate()?;
        let out = Command::new("espeak-ng")
            .arg("-v")
            .arg(&self.voice)
            .arg("-s")
            .arg(self.rate.to_string())
            .arg("-w")
            .arg(path)
            .arg("--")
            .arg(text)
            .output()
            .map_err(|e| program_error("espeak-ng", e))?;
        // espeak-ng exits 0 with a message for an unknown voice.
        let stderr = String::from_utf8_lossy(&out.stderr);
        if !out.status.success() || !stderr.trim().is_empty() || !path.exists() {
            return Err(HilError::channel(
                "speech",
                format!(
                    "espeak-ng could not speak with voice `{}`: {} (list voices with `espeak-ng --voices=en`)",
                    self.voice,
                    stderr.trim()
                ),
            ));
        }
        Ok(())
    }

    /// Speaks `text` into audio, through a scratch file in `scratch`.
    pub fn synthesize(&self, text: &str, scratch: &Path) -> Result<Audio> {
        let path = scratch.join(format!("tts-{}.wav", std::process::id()));
        self.synthesize_to(text, &path)?;
        let audio = Audio::read_wav(&path);
        let _ = std::fs::remove_file(&path);
        audio
    }
}

/// Where the channel's prompts go.
pub trait Voice: Send + std::fmt::Debug {
    /// Says `text`, returning once it has been said.
    fn say(&mut self, text: &str) -> Result<()>;
}

/// Plays prompts on an ALSA device with `aplay` (Debian's `alsa-utils`).
#[derive(Debug)]
pub struct SpeakerVoice {
    /// How prompts are spoken.
    pub voice: EspeakVoice,
    /// ALSA device (`aplay -L` lists them), e.g. `default`.
    pub device: String,
    /// Where the prompt's audio is made.
    pub scratch: PathBuf,
}

impl Voice for SpeakerVoice {
    fn say(&mut self, text: &str) -> Result<()> {
        let path = self
            .scratch
            .join(format!("prompt-{}.wav", std::process::id()));
        self.voice.synthesize_to(text, &path)?;
        let out = Command::new("aplay")
            .args(["-q", "-D", &self.device])
            .arg(&path)
            .output()
            .map_err(|e| program_error("aplay", e));
        let _ = std::fs::remove_file(&path);
        let out = out?;
        if !out.status.success() {
            return Err(HilError::channel(
                "speech",
                format!(
                    "cannot play on audio device `{}`: {} (list output devices with `aplay -L`)",
                    self.device,
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            ));
        }
        Ok(())
    }
}

/// Keeps the prompts' text instead of playing them (replay, tests, the
/// bench): what the person would have heard.
/// Clones share the transcript, so that a test keeps one to read.
#[derive(Debug, Default, Clone)]
pub struct TranscriptVoice {
    said: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

impl TranscriptVoice {
    /// Every prompt said so far, in order.
    pub fn said(&self) -> Vec<String> {
        self.said.lock().map(|s| s.clone()).unwrap_or_default()
    }
}

impl Voice for TranscriptVoice {
    fn say(&mut self, text: &str) -> Result<()> {
        if let Ok(mut s) = self.said.lock() {
            s.push(text.to_string());
        }
        Ok(())
    }
}
