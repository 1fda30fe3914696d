//! The `speech` query channel: says the query, listens, decides; asks
//! again when unsure; hands over or records a decline when it stays unsure.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use hil_core::{
    Answer, ArmId, BoundingBox, HilError, Query, QueryChannel, Response, ResponseType, Result,
};

use crate::audio::{Audio, RECOGNIZER_RATE};
use crate::denoise::{DenoiseSettings, denoise};
use crate::endpoint::{EndpointSettings, Utterance};
use crate::grammar::{Grammar, Meaning, REGIONS, spoken_name};
use crate::listen::{Heard, listen};
use crate::recognize::{Recognition, Recognizer};
use crate::source::AudioSource;
use crate::tts::Voice;

/// What the channel does and how patient it is.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeechSettings {
    /// An answer is taken only at or above this confidence.
    pub threshold: f64,
    /// Times a query is asked again after an unclear answer or none.
    pub max_reasks: usize,
    /// Seconds of listening for speech to start.
    pub timeout_s: f64,
    /// A turn with more than this fraction of samples at full scale is
    /// asked again ("a bit quieter, please") rather than decoded.
    pub max_clipped: f64,
    /// The utterance detector's settings.
    pub endpoint: EndpointSettings,
    /// The noise reduction before the recognizer (none: the audio as
    /// heard).
    pub denoise: Option<DenoiseSettings>,
    /// Where each utterance's WAV and its JSON (transcript, confidence,
    /// timing) are written; none: nothing is kept.
    pub audio_dir: Option<PathBuf>,
    /// Whether the WAV files are kept (consent); the JSON is written either
    /// way when `audio_dir` is set.
    pub keep_audio: bool,
}

impl SpeechSettings {
    /// Checks the settings a config or a caller may set: the threshold is
    /// in [0, 1], the timeout in (0, 600] s, and at most 20 re-asks.
    ///
    /// ```
    /// let mut s = hil_speech::SpeechSettings::default();
    /// assert!(s.validate().is_ok());
    /// s.threshold = f64::NAN;
    /// assert!(s.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<()> {
        Self::check_patience(self.threshold, self.max_reasks, self.timeout_s)?;
        if !(0.0..=1.0).contains(&self.max_clipped) {
            return Err(HilError::invalid_input(
                "max_clipped",
                format!("must be between 0 and 1, got {}", self.max_clipped),
            ));
        }
        Ok(())
    }

    /// The one check of threshold, re-asks and timeout, shared by
    /// [`validate`](Self::validate) and the `speech` channel's config.
    pub(crate) fn check_patience(threshold: f64, max_reasks: usize, timeout_s: f64) -> Result<()> {
        if !(0.0..=1.0).contains(&threshold) {
            return Err(HilError::invalid_input(
                "threshold",
                format!("must be between 0 and 1, got {threshold}"),
            ));
        }
        if !(timeout_s.is_finite() && timeout_s > 0.0 && timeout_s <= 600.0) {
            return Err(HilError::invalid_input(
                "timeout_s",
                format!("must be over 0 and at most 600 seconds, got {timeout_s}"),
            ));
        }
        if max_reasks > 20 {
            return Err(HilError::invalid_input(
                "max_reasks",
                format!("at most 20, got {max_reasks}"),
            ));
        }
        Ok(())
    }
}

impl Default for SpeechSettings {
    fn default() -> Self {
        Self {
            threshold: 0.5,
            max_reasks: 2,
            timeout_s: 8.0,
            max_clipped: 0.01,
            endpoint: EndpointSettings::default(),
            denoise: Some(DenoiseSettings::default()),
            audio_dir: None,
            keep_audio: true,
        }
    }
}

/// Why a turn did not give an answer (or what it gave).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Taken as the answer.
    Accepted,
    /// The person asked to hear the query again.
    Repeat,
    /// Below the confidence threshold, or nothing in the grammar.
    Unsure,
    /// Too loud: clipped.
    Clipped,
    /// Nobody spoke before the timeout.
    Silence,
}

/// One utterance as kept beside the interaction record
/// (`step-T-turn-K.json`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TurnRecord {
    /// The query's step.
    pub t: u64,
    /// The turn (0: the first answer to this query).
    pub turn: usize,
    /// What was heard and decided.
    #[serde(flatten)]
    pub hearing: Hearing,
    /// The WAV file (16 kHz), when audio is kept.
    pub wav: Option<String>,
}

/// The spoken query channel. See the crate README.
pub struct SpeechChannel {
    voice: Box<dyn Voice>,
    source: Box<dyn AudioSource>,
    recognizer: Box<dyn Recognizer>,
    fallback: Option<Box<dyn QueryChannel>>,
    settings: SpeechSettings,
    stop: Arc<AtomicBool>,
    /// Every turn so far (also written to `audio_dir`).
    pub turns: Vec<TurnRecord>,
}

impl std::fmt::Debug for SpeechChannel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpeechChannel")
            .field("voice", &self.voice)
            .field("source", &self.source)
            .field("recognizer", &self.recognizer)
            .field(
                "fallback",
                &self.fallback.as_ref().map(|c| c.name().to_string()),
            )
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

/// The prompt that says `query` and its choices.
pub fn prompt(query: &Query) -> String {
    let mut text = hil_channels::present::question(query);
    match query.kind.response {
        ResponseType::Mcq | ResponseType::OpenEnded => {
            for (i, name) in query.actions.names().iter().enumerate() {
                text.push_str(&format!(
                    " Option {}: {}.",
                    crate::grammar::number_words(i as u64 + 1),
                    spoken_name(name)
                ));
            }
        }
        ResponseType::BoundingBox => {
            text.push_str(" Say where it is: top left, top, top right, left, center, right, bottom left, bottom, or bottom right.");
        }
    }
    text.push_str(" Or say skip, repeat, or I don't know.");
    text
}

/// The sentence said before asking again.
pub const SAY_AGAIN: &str = "Sorry, please say that again.";
/// The sentence said after a clipped answer.
pub const TOO_LOUD: &str =
    "Sorry, that was too loud. Please say it again, a little further from the microphone.";

/// The answer a meaning gives to `query` (none for "repeat").
pub fn answer_for(query: &Query, meaning: Meaning) -> Option<(Answer, Option<ArmId>)> {
    match meaning {
        Meaning::Repeat => None,
        Meaning::Skip | Meaning::DontKnow => Some((Answer::Declined, None)),
        Meaning::Choice(i) => {
            let arm = ArmId(i);
            match query.kind.response {
                // An open-ended answer by voice names an action; the text is
                // its name, so that the record reads like a typed answer.
                ResponseType::OpenEnded => Some((
                    Answer::Text {
                        text: query.actions.names()[i].clone(),
                    },
                    Some(arm),
                )),
                _ => Some((Answer::Action { arm }, Some(arm))),
            }
        }
        Meaning::Region(cell) => {
            let (row, col) = ((cell / 3) as f64, (cell % 3) as f64);
            let bbox = BoundingBox::new(col / 3.0, row / 3.0, (col + 1.0) / 3.0, (row + 1.0) / 3.0);
            debug_assert!(cell < REGIONS.len());
            Some((Answer::BoundingBox { bbox }, None))
        }
    }
}

impl SpeechChannel {
    /// A channel saying prompts with `voice`, hearing answers from
    /// `source`, decoding them with `recognizer`.
    pub fn new(
        voice: Box<dyn Voice>,
        source: Box<dyn AudioSource>,
        recognizer: Box<dyn Recognizer>,
        settings: SpeechSettings,
    ) -> Result<Self> {
        if let Some(dir) = &settings.audio_dir {
            std::fs::create_dir_all(dir).map_err(|e| {
                HilError::channel("speech", format!("cannot create {}: {e}", dir.display()))
            })?;
        }
        let stop = Arc::new(AtomicBool::new(false));
        crate::stop::register(&stop);
        Ok(Self {
            voice,
            source,
            recognizer,
            fallback: None,
            settings,
            stop,
            turns: Vec::new(),
        })
    }

    /// Hands queries it could not understand to `fallback` (the web page,
    /// the terminal) instead of recording a decline.
    pub fn with_fallback(mut self, fallback: Box<dyn QueryChannel>) -> Self {
        self.fallback = Some(fallback);
        self
    }

    /// The flag that stops the channel between utterances: set it (from a
    /// Ctrl-C handler, e.g. `signal_hook::flag::register`, or for every
    /// channel at once with [`crate::stop::stop_all`], as `hil run` does)
    /// and the next turn returns an error instead of listening.
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    fn check_stop(&self, query: &Query) -> Result<()> {
        if self.stop.load(Ordering::SeqCst) {
            return Err(HilError::channel(
                "speech",
                format!(
                    "stopped (Ctrl-C) before the query at step {} was answered; resume with \
                     `hil run --resume LOG`",
                    query.t
                ),
            ));
        }
        Ok(())
    }

    fn keep(&mut self, mut turn: TurnRecord, audio: Option<&Audio>) -> Result<()> {
        if let Some(dir) = &self.settings.audio_dir {
            let stem = format!("step-{}-turn-{}", turn.t, turn.turn);
            if self.settings.keep_audio
                && let Some(a) = audio
            {
                a.write_wav(&dir.join(format!("{stem}.wav")))?;
                turn.wav = Some(format!("{stem}.wav"));
            }
            let path = dir.join(format!("{stem}.json"));
            let json =
                serde_json::to_string_pretty(&turn).map_err(|e| HilError::serde("turn", e))?;
            std::fs::write(&path, json).map_err(|e| {
                HilError::channel("speech", format!("cannot write {}: {e}", path.display()))
            })?;
        }
        self.turns.push(turn);
        Ok(())
    }

    /// One turn: listen, check, decode, decide; the turn is kept.
    fn turn(
        &mut self,
        query: &Query,
        grammar: &Grammar,
        turn: usize,
    ) -> Result<(Outcome, Option<Meaning>)> {
        let mut stream = self.source.open(query, turn)?;
        let hearing = hear(
            stream.as_mut(),
            &self.settings,
            self.recognizer.as_mut(),
            grammar,
        )?;
        drop(stream);
        let outcome = hearing.outcome;
        let meaning = hearing.recognition.as_ref().and_then(|r| r.meaning);
        let audio = hearing.audio.clone();
        let record = TurnRecord {
            t: query.t,
            turn,
            hearing,
            wav: None,
        };
        self.keep(record, audio.as_ref())?;
        Ok((outcome, meaning))
    }
}

/// What one turn of listening heard and decided.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Hearing {
    /// What became of it.
    pub outcome: Outcome,
    /// The recognizer's result (none for silence or clipping).
    pub recognition: Option<Recognition>,
    /// Stream seconds to the start of speech.
    pub speech_start_s: Option<f64>,
    /// Stream seconds to the end of speech.
    pub speech_end_s: Option<f64>,
    /// End of speech to decision, in ms: the detector's hangover (stream
    /// time) plus the time spent checking and decoding.
    pub latency_ms: Option<f64>,
    /// Fraction of clipped samples.
    pub clipped_fraction: f64,
    /// The utterance (16 kHz), if there was one (kept as a WAV file, not
    /// in the JSON).
    #[serde(skip)]
    pub audio: Option<Audio>,
}

/// What the recognizer hears of an utterance: its samples with the
/// background measured before it taken out (when the settings ask for it
/// and there was background to measure), as 16-bit samples.
pub fn recognizer_input(utterance: &Utterance, settings: &SpeechSettings) -> Result<Vec<i16>> {
    let samples = match (&settings.denoise, &utterance.background_spectrum) {
        (Some(d), Some(noise)) => denoise(&utterance.samples, noise, *d)?,
        _ => utterance.samples.clone(),
    };
    Ok(Audio {
        rate: RECOGNIZER_RATE,
        samples,
    }
    .to_i16())
}

/// Listens to `stream` once and decides, as the channel does on every
/// turn (and `hil bench speech` on every utterance of its corpus).
pub fn hear(
    stream: &mut dyn crate::source::AudioStream,
    settings: &SpeechSettings,
    recognizer: &mut dyn Recognizer,
    grammar: &Grammar,
) -> Result<Hearing> {
    let utterance = match listen(stream, settings.endpoint, settings.timeout_s)? {
        Heard::Nothing { .. } => {
            return Ok(Hearing {
                outcome: Outcome::Silence,
                recognition: None,
                speech_start_s: None,
                speech_end_s: None,
                latency_ms: None,
                clipped_fraction: 0.0,
                audio: None,
            });
        }
        Heard::Utterance(u) => u,
    };
    let decided_at = Instant::now();
    let audio = Audio {
        rate: RECOGNIZER_RATE,
        samples: utterance.samples.clone(),
    };
    let clipped = audio.clipped_fraction();
    let (outcome, recognition) = if clipped > settings.max_clipped {
        (Outcome::Clipped, None)
    } else {
        let r = recognizer.recognize(grammar, &recognizer_input(&utterance, settings)?)?;
        let outcome = match r.meaning {
            Some(_) if r.confidence < settings.threshold => Outcome::Unsure,
            Some(Meaning::Repeat) => Outcome::Repeat,
            Some(_) => Outcome::Accepted,
            None => Outcome::Unsure,
        };
        (outcome, Some(r))
    };
    let hangover_ms = (utterance.closed_s - utterance.speech_end_s) * 1000.0;
    Ok(Hearing {
        outcome,
        recognition,
        speech_start_s: Some(utterance.speech_start_s),
        speech_end_s: Some(utterance.speech_end_s),
        latency_ms: Some(hangover_ms + decided_at.elapsed().as_secs_f64() * 1000.0),
        clipped_fraction: clipped,
        audio: Some(audio),
    })
}

impl QueryChannel for SpeechChannel {
    fn name(&self) -> &str {
        "speech"
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        let start = Instant::now();
        let grammar = Grammar::for_query(query);
        let mut heard_anything = false;
        let mut unclear = 0usize;
        let mut turn = 0usize;
        self.check_stop(query)?;
        self.voice.say(&prompt(query))?;
        loop {
            self.check_stop(query)?;
            let (outcome, meaning) = self.turn(query, &grammar, turn)?;
            turn += 1;
            heard_anything |= outcome != Outcome::Silence;
            let again = match (outcome, meaning) {
                (Outcome::Accepted, Some(m)) => {
                    if let Some((answer, arm)) = answer_for(query, m) {
                        hil_channels::present::validate_answer(query, &answer)?;
                        let seconds = start.elapsed().as_secs_f64();
                        return Ok(Response::new(answer, arm, Some(seconds)));
                    }
                    prompt(query)
                }
                (Outcome::Repeat, _) => prompt(query),
                (Outcome::Clipped, _) => TOO_LOUD.to_string(),
                _ => SAY_AGAIN.to_string(),
            };
            // A repeat counts too: a loop of "repeat" ends like any other.
            unclear += 1;
            if unclear > self.settings.max_reasks {
                break;
            }
            self.check_stop(query)?;
            self.voice.say(&again)?;
        }
        self.check_stop(query)?;
        if let Some(fallback) = self.fallback.as_mut() {
            self.voice.say("I'll ask on the screen instead.")?;
            return fallback.ask(query);
        }
        let answer = if heard_anything {
            Answer::Declined
        } else {
            Answer::TimedOut
        };
        let seconds = start.elapsed().as_secs_f64();
        Ok(Response::new(answer, None, Some(seconds)))
    }
}
