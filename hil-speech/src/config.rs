//! `[channel] type = "speech"`: the spoken query channel in a config.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use hil_config::{QueryChannelConfig, TaskContext};
use hil_core::{HilError, QueryChannel, Result};

use crate::tts::EspeakVoice;

/// Config of the speech channel:
///
/// ```toml
/// [channel]
/// type = "speech"
/// device = "default"          # ALSA capture device (`arecord -L`)
/// output_device = "default"   # ALSA playback device (`aplay -L`)
/// voice = { voice = "en-us", rate = 160 }
/// threshold = 0.5             # least confidence taken as an answer
/// max_reasks = 2
/// timeout_s = 8.0
/// audio_dir = "session-audio" # WAV + JSON per utterance (relative to the config)
/// keep_audio = true           # false: no WAV, only transcripts and timing
/// denoise = true              # false: the recognizer hears the audio unfiltered
/// fallback = { type = "terminal" }   # optional; else a decline
/// ```
///
/// `replay = ["a.wav", "b.wav"]` answers from WAV files, one per turn,
/// instead of the device (replaying a recorded session); prompts are then
/// not played.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeechChannelConfig {
    /// ALSA capture device.
    #[serde(default = "default_device")]
    pub device: String,
    /// ALSA playback device.
    #[serde(default = "default_device")]
    pub output_device: String,
    /// How prompts are spoken.
    #[serde(default)]
    pub voice: EspeakVoice,
    /// Least confidence taken as an answer, in [0, 1].
    #[serde(default = "default_threshold")]
    pub threshold: f64,
    /// Times a query is asked again.
    #[serde(default = "default_reasks")]
    pub max_reasks: usize,
    /// Seconds of listening for speech to start.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Where utterances are kept (relative to the config's folder).
    #[serde(default)]
    pub audio_dir: Option<PathBuf>,
    /// Whether WAV files are kept (consent).
    #[serde(default = "yes")]
    pub keep_audio: bool,
    /// Whether the background noise is filtered out before the recognizer
    /// ([`crate::denoise`], with its default settings); off, it hears the
    /// audio as captured (a quiet room, or to compare).
    #[serde(default = "yes")]
    pub denoise: bool,
    /// The pocketsphinx model folder (Debian's layout).
    #[serde(default = "default_model")]
    pub model_dir: PathBuf,
    /// Where a query goes after `max_reasks` unclear answers.
    #[serde(default)]
    pub fallback: Option<Box<dyn QueryChannelConfig>>,
    /// Answer from these WAV files instead of the device.
    #[serde(default)]
    pub replay: Option<Vec<PathBuf>>,
}

fn default_device() -> String {
    "default".into()
}
fn default_threshold() -> f64 {
    0.5
}
fn default_reasks() -> usize {
    2
}
fn default_timeout() -> f64 {
    8.0
}
fn yes() -> bool {
    true
}
fn default_model() -> PathBuf {
    crate::recognize::DEFAULT_MODEL_DIR.into()
}

impl SpeechChannelConfig {
    /// The channel settings this config asks for (`audio_dir` resolved
    /// against the config's folder).
    pub fn settings(&self, ctx: &TaskContext) -> crate::SpeechSettings {
        crate::SpeechSettings {
            threshold: self.threshold,
            max_reasks: self.max_reasks,
            timeout_s: self.timeout_s,
            audio_dir: self.audio_dir.as_ref().map(|d| ctx.base().base_dir.join(d)),
            keep_audio: self.keep_audio,
            denoise: self.denoise.then(crate::denoise::DenoiseSettings::default),
            ..Default::default()
        }
    }
}

#[typetag::serde(name = "speech")]
impl QueryChannelConfig for SpeechChannelConfig {
    fn validate(&self) -> Result<()> {
        crate::SpeechSettings::check_patience(self.threshold, self.max_reasks, self.timeout_s)?;
        for (field, d) in [
            ("device", &self.device),
            ("output_device", &self.output_device),
        ] {
            if d.trim().is_empty() || d.starts_with('-') {
                return Err(HilError::invalid_input(
                    field,
                    "name an ALSA device (`arecord -L` / `aplay -L` list them), e.g. default",
                ));
            }
        }
        self.voice.validate()?;
        if let Some(f) = &self.fallback {
            f.validate()?;
        }
        Ok(())
    }

    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        self.validate()?;
        build(self, ctx)
    }
}

#[cfg(not(feature = "engines"))]
fn build(_config: &SpeechChannelConfig, _ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
    Err(HilError::channel(
        "speech",
        "this program was built without speech: run scripts/setup-speech, then build hil with \
         `--features speech`",
    ))
}

#[cfg(feature = "engines")]
fn build(config: &SpeechChannelConfig, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
    use crate::source::{AudioSource, DeviceSource, FileSource};
    use crate::tts::{SpeakerVoice, TranscriptVoice, Voice};
    let recognizer = Box::new(crate::recognize::SphinxRecognizer::new(&config.model_dir)?);
    let (source, voice): (Box<dyn AudioSource>, Box<dyn Voice>) = match &config.replay {
        Some(files) => (
            Box::new(FileSource::new(
                files.iter().map(|f| ctx.base().base_dir.join(f)),
            )),
            Box::new(TranscriptVoice::default()),
        ),
        None => {
            let device = DeviceSource {
                device: config.device.clone(),
                rate: crate::audio::RECOGNIZER_RATE,
                seconds: (config.timeout_s.ceil() as u32).saturating_add(30),
            };
            device.probe()?;
            (
                Box::new(device),
                Box::new(SpeakerVoice {
                    voice: config.voice.clone(),
                    device: config.output_device.clone(),
                    scratch: std::env::temp_dir(),
                }),
            )
        }
    };
    let mut channel = crate::SpeechChannel::new(voice, source, recognizer, config.settings(ctx))?;
    if let Some(f) = &config.fallback {
        channel = channel.with_fallback(f.build(ctx)?);
    }
    Ok(Box::new(channel))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Box<dyn QueryChannelConfig> {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_config_reads_with_defaults_and_bad_values_name_their_field() {
        let c = parse("type = \"speech\"\nfallback = { type = \"terminal\" }\n");
        c.validate().unwrap();
        for (text, field) in [
            ("threshold = 1.5", "threshold"),
            ("timeout_s = 0.0", "timeout_s"),
            ("max_reasks = 99", "max_reasks"),
            ("device = \"\"", "device"),
            ("voice = { voice = \"en-us\", rate = 5 }", "rate"),
        ] {
            let c = parse(&format!("type = \"speech\"\n{text}\n"));
            match c.validate() {
                Err(HilError::InvalidInput { what, .. }) => assert_eq!(what, field),
                other => panic!("{text}: {other:?}"),
            }
        }
    }

    #[test]
    fn the_noise_filter_is_on_unless_the_config_turns_it_off() {
        let actions = hil_core::ActionSpace::new(["a", "b"]).unwrap();
        let ctx = TaskContext::new(hil_config::BuildContext::new(".", 0), actions, 2);
        let settings = |text: &str| {
            toml::from_str::<SpeechChannelConfig>(text)
                .unwrap()
                .settings(&ctx)
        };
        assert_eq!(
            settings("").denoise,
            Some(crate::denoise::DenoiseSettings::default())
        );
        assert_eq!(settings("denoise = true").denoise, settings("").denoise);
        assert_eq!(settings("denoise = false").denoise, None);
        assert!(toml::from_str::<SpeechChannelConfig>("denoise = \"no\"").is_err());
    }
}
