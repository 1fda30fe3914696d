//! Samples between capture and the recognizer: reading and writing WAV,
//! converting to the recognizer's 16 kHz mono, measuring clipping, and
//! mixing noise at a chosen signal-to-noise ratio (the bench's corpus).

use std::path::Path;

use hil_core::{HilError, Result};

/// The recognizer's sample rate (the en-us acoustic model's).
pub const RECOGNIZER_RATE: u32 = 16_000;

/// Mono audio: samples in [-1, 1] at `rate` Hz.
#[derive(Clone, Debug, PartialEq)]
pub struct Audio {
    /// Samples per second.
    pub rate: u32,
    /// The samples (mono).
    pub samples: Vec<f32>,
}

fn wav_error(path: &Path, e: impl std::fmt::Display) -> HilError {
    HilError::channel("speech", format!("{}: {e}", path.display()))
}

impl Audio {
    /// Duration in seconds.
    pub fn seconds(&self) -> f64 {
        self.samples.len() as f64 / f64::from(self.rate.max(1))
    }

    /// Reads a WAV file of any rate, 8–32-bit integer or float samples and
    /// any number of channels (averaged to mono).
    pub fn read_wav(path: &Path) -> Result<Self> {
        let reader = hound::WavReader::open(path).map_err(|e| wav_error(path, e))?;
        let spec = reader.spec();
        let channels = usize::from(spec.channels.max(1));
        let interleaved: Vec<f32> = match spec.sample_format {
            hound::SampleFormat::Float => reader
                .into_samples::<f32>()
                .collect::<std::result::Result<_, _>>()
                .map_err(|e| wav_error(path, e))?,
            hound::SampleFormat::Int => {
                let scale = 1.0 / (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f32;
                reader
                    .into_samples::<i32>()
                    .map(|s| s.map(|v| v as f32 * scale))
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|e| wav_error(path, e))?
            }
        };
        if spec.sample_rate == 0 {
            return Err(wav_error(path, "the sample rate is 0"));
        }
        let samples = interleaved
            .chunks(channels)
            .map(|c| c.iter().sum::<f32>() / c.len() as f32)
            .collect();
        Ok(Self {
            rate: spec.sample_rate,
            samples,
        })
    }

    /// Writes 16-bit mono PCM.
    pub fn write_wav(&self, path: &Path) -> Result<()> {
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: self.rate,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut w = hound::WavWriter::create(path, spec).map_err(|e| wav_error(path, e))?;
        for &s in &self.samples {
            w.write_sample(to_i16(s)).map_err(|e| wav_error(path, e))?;
        }
        w.finalize().map_err(|e| wav_error(path, e))
    }

    /// The audio at `rate` Hz (a copy when it already is).
    pub fn resampled(&self, rate: u32) -> Self {
        Self {
            rate,
            samples: resample(&self.samples, self.rate, rate),
        }
    }

    /// The samples as the recognizer takes them (16-bit).
    pub fn to_i16(&self) -> Vec<i16> {
        self.samples.iter().map(|&s| to_i16(s)).collect()
    }

    /// The fraction of samples at full scale (|s| ≥ 0.999): clipping.
    pub fn clipped_fraction(&self) -> f64 {
        if self.samples.is_empty() {
            return 0.0;
        }
        let n = self.samples.iter().filter(|s| s.abs() >= 0.999).count();
        n as f64 / self.samples.len() as f64
    }

    /// Mean power (mean square).
    pub fn power(&self) -> f64 {
        mean_square(&self.samples)
    }
}

fn mean_square(s: &[f32]) -> f64 {
    if s.is_empty() {
        return 0.0;
    }
    s.iter().map(|&v| f64::from(v) * f64::from(v)).sum::<f64>() / s.len() as f64
}

fn to_i16(s: f32) -> i16 {
    (s.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// Band-limited resampling (windowed sinc, 16 zero crossings, cut-off at
/// the lower of the two Nyquist frequencies): speech from a 44.1 or 48 kHz
/// microphone, or espeak-ng's 22.05 kHz, becomes the recognizer's 16 kHz
/// without aliasing.
pub fn resample(input: &[f32], from: u32, to: u32) -> Vec<f32> {
    if from == to || input.is_empty() {
        return input.to_vec();
    }
    const ZEROS: f64 = 16.0;
    let ratio = f64::from(to) / f64::from(from);
    let cutoff = ratio.min(1.0); // of the input's Nyquist frequency
    let half_width = ZEROS / cutoff; // input samples each side
    let n_out = ((input.len() as f64) * ratio).floor() as usize;
    let mut out = Vec::with_capacity(n_out);
    for j in 0..n_out {
        let centre = j as f64 / ratio;
        let lo = (centre - half_width).ceil().max(0.0) as usize;
        let hi = ((centre + half_width).floor() as usize).min(input.len() - 1);
        let mut acc = 0.0f64;
        for (i, &x) in input.iter().enumerate().take(hi + 1).skip(lo) {
            let d = i as f64 - centre;
            let arg = d * cutoff;
            let sinc = if arg.abs() < 1e-12 {
                1.0
            } else {
                (std::f64::consts::PI * arg).sin() / (std::f64::consts::PI * arg)
            };
            // Hann window over ±half_width.
            let w = 0.5 + 0.5 * (std::f64::consts::PI * d / half_width).cos();
            acc += f64::from(x) * sinc * w * cutoff;
        }
        out.push(acc as f32);
    }
    out
}

/// `speech` plus `noise` scaled so that the speech's power over the noise's
/// is `snr_db` (the noise is repeated or cut to the speech's length; both at
/// the same rate).
pub fn mix_at_snr(speech: &Audio, noise: &Audio, snr_db: f64) -> Result<Audio> {
    if speech.rate != noise.rate {
        return Err(HilError::invalid_input(
            "noise",
            format!("{} Hz noise for {} Hz speech", noise.rate, speech.rate),
        ));
    }
    let noise_power = noise.power();
    if noise.samples.is_empty() || noise_power <= 0.0 {
        return Err(HilError::invalid_input("noise", "the noise is silent"));
    }
    // The speech's power where it is voiced: leading/trailing silence
    // would otherwise make every SNR look better than it is.
    let voiced: Vec<f32> = speech
        .samples
        .iter()
        .copied()
        .filter(|s| s.abs() > 1e-3)
        .collect();
    let gain = (mean_square(&voiced) / noise_power / 10f64.powf(snr_db / 10.0)).sqrt() as f32;
    let samples = speech
        .samples
        .iter()
        .zip(noise.samples.iter().cycle())
        .map(|(&s, &n)| s + gain * n)
        .collect();
    Ok(Audio {
        rate: speech.rate,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone(freq: f64, rate: u32, seconds: f64) -> Vec<f32> {
        (0..(f64::from(rate) * seconds) as usize)
            .map(|i| {
                (0.5 * (2.0 * std::f64::consts::PI * freq * i as f64 / f64::from(rate)).sin())
                    as f32
            })
            .collect()
    }

    #[test]
    fn resampling_keeps_a_tone_and_removes_what_cannot_be_represented() {
        // 1 kHz survives 44.1 kHz → 16 kHz at its amplitude...
        let kept = resample(&tone(1000.0, 44_100, 0.5), 44_100, 16_000);
        assert_eq!(kept.len(), 8000);
        let p = mean_square(&kept[1000..7000]);
        assert!((p - 0.125).abs() < 0.005, "{p}");
        // ...while 12 kHz (above the new 8 kHz Nyquist) is filtered out
        // instead of aliasing to 4 kHz.
        let gone = resample(&tone(12_000.0, 44_100, 0.5), 44_100, 16_000);
        assert!(mean_square(&gone[1000..7000]) < 0.002);
    }

    #[test]
    fn wav_round_trips_and_stereo_becomes_mono() {
        let dir = std::env::temp_dir().join(format!("hil-speech-wav-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.wav");
        let a = Audio {
            rate: 16_000,
            samples: vec![0.0, 0.5, -0.5, 1.0],
        };
        a.write_wav(&path).unwrap();
        let b = Audio::read_wav(&path).unwrap();
        assert_eq!(b.rate, 16_000);
        assert!(
            a.samples
                .iter()
                .zip(&b.samples)
                .all(|(x, y)| (x - y).abs() < 1e-3)
        );
        assert!((b.clipped_fraction() - 0.25).abs() < 1e-9);
        let spec = hound::WavSpec {
            channels: 2,
            sample_rate: 8000,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let stereo = dir.join("s.wav");
        let mut w = hound::WavWriter::create(&stereo, spec).unwrap();
        for s in [16384i16, 0, 16384, 0] {
            w.write_sample(s).unwrap();
        }
        w.finalize().unwrap();
        let m = Audio::read_wav(&stereo).unwrap();
        assert_eq!((m.rate, m.samples.len()), (8000, 2));
        assert!((m.samples[0] - 0.25).abs() < 1e-3);
        let missing = Audio::read_wav(&dir.join("nope.wav")).unwrap_err();
        assert!(missing.to_string().contains("nope.wav"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn noise_is_mixed_at_the_asked_ratio() {
        let speech = Audio {
            rate: 8000,
            samples: tone(440.0, 8000, 1.0),
        };
        let noise = Audio {
            rate: 8000,
            samples: tone(97.0, 8000, 0.3),
        };
        let mixed = mix_at_snr(&speech, &noise, 10.0).unwrap();
        let added: Vec<f32> = mixed
            .samples
            .iter()
            .zip(&speech.samples)
            .map(|(m, s)| m - s)
            .collect();
        let snr = 10.0 * (speech.power() / mean_square(&added)).log10();
        assert!((snr - 10.0).abs() < 0.3, "{snr}");
        let silent = Audio {
            rate: 8000,
            samples: vec![0.0; 10],
        };
        assert!(mix_at_snr(&speech, &silent, 10.0).is_err());
    }
}
