//! Finding an utterance in a stream of 16 kHz samples: an energy detector
//! that follows the background's level, so that it works in a quiet room
//! and next to a running fan alike. It also measures the background's
//! power spectrum, which the noise reduction before the recognizer takes
//! out ([`crate::denoise`]).

use crate::denoise::{BINS, WINDOW, power_spectrum};

/// Frame length: 10 ms at 16 kHz.
pub const FRAME: usize = 160;

/// The detector's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndpointSettings {
    /// A frame is speech when its level is this many dB above the
    /// background's.
    pub above_background_db: f64,
    /// ...and above this absolute level (dB full scale).
    pub floor_dbfs: f64,
    /// Speech frames in a row that start an utterance.
    pub start_frames: usize,
    /// Silent frames after the last speech frame that end it (the
    /// hangover: part of the latency from end of speech to decision).
    pub end_frames: usize,
    /// Audio kept before the first speech frame, in frames.
    pub preroll_frames: usize,
    /// Longest utterance, in frames; a longer one is cut there.
    pub max_frames: usize,
}

impl Default for EndpointSettings {
    fn default() -> Self {
        Self {
            above_background_db: 6.0,
            floor_dbfs: -50.0,
            start_frames: 3,
            end_frames: 25,
            preroll_frames: 20,
            max_frames: 1000,
        }
    }
}

/// An utterance found in a stream.
#[derive(Clone, Debug, PartialEq)]
pub struct Utterance {
    /// Its samples (16 kHz), from a little before the speech starts to the
    /// end of the hangover.
    pub samples: Vec<f32>,
    /// Stream time (seconds from the start of listening) of the first
    /// speech frame.
    pub speech_start_s: f64,
    /// Stream time of the last speech frame's end: the end of speech.
    pub speech_end_s: f64,
    /// Stream time at which the detector closed the utterance.
    pub closed_s: f64,
    /// The background's mean power spectrum ([`crate::denoise::BINS`]
    /// bins), from the audio before the utterance's preroll; none when the
    /// speech started too early to measure it.
    pub background_spectrum: Option<Vec<f64>>,
}

/// The mean power spectrum of background frames: a plain mean over the
/// first `MEAN_FRAMES`, then a running one that follows a changing
/// background.
#[derive(Debug, Default)]
struct BackgroundSpectrum {
    mean: Vec<f64>,
    frames: usize,
}

/// Background frames after which the spectrum's mean becomes a running
/// mean (over about this many frames).
const MEAN_FRAMES: usize = 50;

impl BackgroundSpectrum {
    fn add(&mut self, power: &[f64]) {
        self.frames += 1;
        if self.mean.is_empty() {
            self.mean = power.to_vec();
            return;
        }
        let w = 1.0 / self.frames.min(MEAN_FRAMES) as f64;
        for (m, p) in self.mean.iter_mut().zip(power) {
            *m += w * (p - *m);
        }
    }
}

/// Feeds frames, returns the utterance once it is closed.
#[derive(Debug)]
pub struct Endpointer {
    settings: EndpointSettings,
    background_db: Option<f64>,
    pending: Vec<f32>,
    frames_seen: usize,
    history: std::collections::VecDeque<Vec<f32>>,
    run: usize,
    speech: Option<Speech>,
    spectrum: BackgroundSpectrum,
}

#[derive(Debug)]
struct Speech {
    samples: Vec<f32>,
    start_frame: usize,
    last_speech_frame: usize,
    frames: usize,
}

fn level_db(frame: &[f32]) -> f64 {
    let ms = frame
        .iter()
        .map(|&s| f64::from(s) * f64::from(s))
        .sum::<f64>()
        / frame.len() as f64;
    10.0 * (ms + 1e-12).log10()
}

impl Endpointer {
    /// A detector with `settings`.
    pub fn new(settings: EndpointSettings) -> Self {
        Self {
            settings,
            background_db: None,
            pending: Vec::new(),
            frames_seen: 0,
            history: Default::default(),
            run: 0,
            speech: None,
            spectrum: BackgroundSpectrum::default(),
        }
    }

    /// Stream time consumed so far, in seconds.
    pub fn seconds(&self) -> f64 {
        (self.frames_seen * FRAME) as f64 / 16_000.0
    }

    /// Whether speech has started (an utterance is open).
    pub fn in_speech(&self) -> bool {
        self.speech.is_some()
    }

    /// Takes more samples; returns the utterance when one is complete.
    pub fn push(&mut self, samples: &[f32]) -> Option<Utterance> {
        self.pending.extend_from_slice(samples);
        let mut done = None;
        let mut offset = 0;
        while done.is_none() && self.pending.len() - offset >= FRAME {
            let frame = self.pending[offset..offset + FRAME].to_vec();
            offset += FRAME;
            done = self.frame(frame);
        }
        self.pending.drain(..offset);
        done
    }

    /// Ends the stream: an open utterance is closed as it is.
    pub fn finish(&mut self) -> Option<Utterance> {
        let s = self.speech.take()?;
        Some(self.close(s))
    }

    fn close(&self, s: Speech) -> Utterance {
        let t = |f: usize| (f * FRAME) as f64 / 16_000.0;
        Utterance {
            samples: s.samples,
            speech_start_s: t(s.start_frame),
            speech_end_s: t(s.last_speech_frame + 1),
            closed_s: t(self.frames_seen),
            background_spectrum: (self.spectrum.frames > 0).then(|| self.spectrum.mean.clone()),
        }
    }

    fn frame(&mut self, frame: Vec<f32>) -> Option<Utterance> {
        let st = self.settings;
        let level = level_db(&frame);
        let index = self.frames_seen;
        self.frames_seen += 1;
        let background = *self.background_db.get_or_insert(level);
        let is_speech = level > background + st.above_background_db && level > st.floor_dbfs;
        if !is_speech && self.speech.is_none() {
            // Follow the background: quickly down, slowly up.
            let rate = if level < background { 0.3 } else { 0.02 };
            self.background_db = Some(background + rate * (level - background));
        }
        if let Some(s) = &mut self.speech {
            s.samples.extend_from_slice(&frame);
            s.frames += 1;
            if is_speech {
                s.last_speech_frame = index;
            }
            if index - s.last_speech_frame >= st.end_frames || s.frames >= st.max_frames {
                let s = self.speech.take()?;
                return Some(self.close(s));
            }
            return None;
        }
        self.run = if is_speech { self.run + 1 } else { 0 };
        self.history.push_back(frame);
        while self.history.len() > st.preroll_frames + st.start_frames {
            // A frame older than the preroll is background: the speech's
            // onset, softer than the detector's threshold, stays out of
            // the measured spectrum.
            let old = self.history.pop_front()?;
            if let Some(next) = self.history.front() {
                let mut window = old;
                window.extend_from_slice(&next[..WINDOW.saturating_sub(FRAME).min(next.len())]);
                if let Some(power) = power_spectrum(&window) {
                    debug_assert_eq!(power.len(), BINS);
                    self.spectrum.add(&power);
                }
            }
        }
        if self.run >= st.start_frames {
            let samples: Vec<f32> = self.history.drain(..).flatten().collect();
            self.speech = Some(Speech {
                frames: samples.len() / FRAME,
                samples,
                start_frame: index + 1 - st.start_frames,
                last_speech_frame: index,
            });
            self.run = 0;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_signals::{noise, tone as tone_at};

    fn tone(n: usize, amp: f32) -> Vec<f32> {
        tone_at(n, amp, 0.2)
    }

    #[test]
    fn an_utterance_in_background_noise_is_found_with_its_times() {
        let mut stream = noise(8000, 0.01, 7); // 0.5 s of background
        stream.extend(
            tone(16_000, 0.3)
                .iter()
                .zip(noise(16_000, 0.01, 9))
                .map(|(a, b)| a + b),
        );
        stream.extend(noise(16_000, 0.01, 11));
        let mut ep = Endpointer::new(EndpointSettings::default());
        let mut found = None;
        for chunk in stream.chunks(1234) {
            if let Some(u) = ep.push(chunk) {
                found = Some(u);
                break;
            }
        }
        let u = found.expect("an utterance");
        assert!(
            (u.speech_start_s - 0.5).abs() < 0.02,
            "{}",
            u.speech_start_s
        );
        assert!((u.speech_end_s - 1.5).abs() < 0.02, "{}", u.speech_end_s);
        assert!((u.closed_s - u.speech_end_s - 0.25).abs() < 0.011);
    }

    #[test]
    fn silence_and_steady_noise_are_no_utterance() {
        let mut ep = Endpointer::new(EndpointSettings::default());
        assert!(ep.push(&vec![0.0; 32_000]).is_none());
        assert!(ep.finish().is_none());
        let mut ep = Endpointer::new(EndpointSettings::default());
        assert!(ep.push(&noise(32_000, 0.05, 3)).is_none());
        assert!(ep.finish().is_none());
    }

    #[test]
    fn the_background_spectrum_is_measured_before_the_speech_and_its_onset() {
        // 0.6 s of noise, of which the last 0.15 s carry the word's soft
        // onset (below the detector's threshold), then the word.
        let mut stream = noise(9600, 0.01, 7);
        let onset: Vec<f32> = tone(2400, 0.01)
            .iter()
            .zip(noise(2400, 0.01, 5))
            .map(|(a, b)| a + b)
            .collect();
        stream.extend(onset);
        stream.extend(tone(16_000, 0.3));
        stream.extend(noise(16_000, 0.01, 11));
        let mut ep = Endpointer::new(EndpointSettings::default());
        let u = ep.push(&stream).expect("an utterance");
        let spectrum = u.background_spectrum.expect("background measured");
        assert_eq!(spectrum.len(), BINS);
        // The tone (0.2 rad per sample) falls in bin 16 of 512: nothing of
        // it in the background's spectrum.
        let mut sorted = spectrum.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[BINS / 2];
        assert!(spectrum[16] < 3.0 * median, "{} vs {median}", spectrum[16]);
    }

    #[test]
    fn speech_within_the_preroll_of_the_start_has_no_background_measured() {
        let mut ep = Endpointer::new(EndpointSettings::default());
        // 50 ms of background: all of it in the utterance's preroll.
        let mut stream = noise(800, 0.01, 3);
        stream.extend(tone(16_000, 0.3));
        stream.extend(vec![0.0; 8000]);
        let u = ep.push(&stream).expect("an utterance");
        assert_eq!(u.background_spectrum, None);
    }
}
