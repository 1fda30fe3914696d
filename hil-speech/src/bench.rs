//! `hil bench speech`: builds a corpus at run time (espeak-ng says every
//! answer of every query kind in several voices and rates; sox makes the
//! noise, mixed in at several signal-to-noise ratios) and hears each
//! utterance exactly as the channel does ([`crate::channel::hear`]).

use std::path::{Path, PathBuf};
use std::process::Command;

use hil_core::{Context, HilError, Item, Query, QueryKind, ResponseType, Result};

use crate::audio::{Audio, mix_at_snr};
use crate::channel::{Outcome, SpeechSettings, hear};
use crate::grammar::{Grammar, Meaning};
use crate::recognize::SphinxRecognizer;
use crate::source::MemoryStream;
use crate::tts::EspeakVoice;

/// What the bench runs.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchSettings {
    /// espeak-ng voices.
    pub voices: Vec<String>,
    /// Speaking rates, words per minute.
    pub rates: Vec<u32>,
    /// Signal-to-noise ratios in dB (`None`: no noise).
    pub snrs_db: Vec<Option<f64>>,
    /// The channel's settings (threshold, detector).
    pub channel: SpeechSettings,
    /// The recognizer's model folder.
    pub model_dir: PathBuf,
    /// Scratch folder for the corpus.
    pub scratch: PathBuf,
}

impl Default for BenchSettings {
    fn default() -> Self {
        Self {
            voices: ["en-us", "en-gb", "en-us+f3", "en-gb-scotland"]
                .map(String::from)
                .to_vec(),
            rates: vec![130, 160, 200],
            snrs_db: vec![None, Some(20.0), Some(10.0), Some(5.0)],
            channel: SpeechSettings::default(),
            model_dir: crate::sphinx::DEFAULT_MODEL_DIR.into(),
            scratch: std::env::temp_dir().join(format!("hil-bench-speech-{}", std::process::id())),
        }
    }
}

/// The figures at one noise level.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BenchRow {
    /// Signal-to-noise ratio (None: clean).
    pub snr_db: Option<f64>,
    /// Utterances heard.
    pub n: usize,
    /// Fraction whose recognized meaning is the one said (whatever the
    /// confidence).
    pub accuracy: f64,
    /// Fraction accepted at or above the threshold with a wrong meaning.
    pub false_accept: f64,
    /// Fraction not accepted (below the threshold, nothing in the grammar,
    /// clipped, no speech found): the channel would ask again.
    pub reask: f64,
    /// Mean latency from end of speech to decision, ms.
    pub latency_mean_ms: f64,
    /// 95th percentile of that latency, ms.
    pub latency_p95_ms: f64,
}

/// The query kinds of the corpus, each with the feeding task's actions.
fn queries() -> Vec<Query> {
    ResponseType::ALL
        .iter()
        .map(|&response| {
            Query::new(
                1,
                Item::new(0, "banana"),
                QueryKind {
                    response,
                    ..Default::default()
                },
                // The six actions of the feeding task, spelled as there.
                hil_core::ActionSpace::new(["VS0", "VS90", "TV0", "TV90", "TA0", "TA90"])
                    .expect("six distinct names"),
                Context::new(vec![0.0]).expect("a finite context"),
            )
        })
        .collect()
}

/// Pink noise from sox (`-R`: the same every run), read back.
pub fn sox_noise(path: &Path, rate: u32, seconds: u32) -> Result<Audio> {
    let out = Command::new("sox")
        .args(["-R", "-n", "-c", "1", "-b", "16", "-r"])
        .arg(rate.to_string())
        .arg(path)
        .args(["synth", &seconds.to_string(), "pinknoise"])
        .output()
        .map_err(|e| {
            HilError::channel(
                "speech",
                format!("cannot run sox ({e}): run scripts/setup-speech"),
            )
        })?;
    if !out.status.success() {
        return Err(HilError::channel(
            "speech",
            format!(
                "sox failed: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        ));
    }
    Audio::read_wav(path)
}

/// Every (grammar, phrase, meaning) of every query kind: what the corpus
/// says.
pub fn corpus_items() -> Vec<(Grammar, String, Meaning)> {
    let mut items = Vec::new();
    for q in queries() {
        let g = Grammar::for_query(&q);
        for (phrase, meaning) in g.phrases().to_vec() {
            items.push((g.clone(), phrase, meaning));
        }
    }
    items
}

/// One utterance of the corpus.
#[derive(Debug)]
pub struct CorpusUtterance<'a> {
    /// The grammar of the query it answers.
    pub grammar: &'a Grammar,
    /// What is said...
    pub phrase: &'a str,
    /// ...and what it means.
    pub meaning: Meaning,
    /// The voice and rate saying it.
    pub voice: &'a EspeakVoice,
    /// Its index in the SNRs walked (`None` among them: clean).
    pub snr_index: usize,
    /// The audio: the phrase in silence, with the noise mixed in.
    pub audio: Audio,
}

/// Makes every utterance of the corpus — each phrase of [`corpus_items`]
/// in each voice and rate, clean or mixed with sox's pink noise at each of
/// `snrs_db` — and hands it to `each`. The k-th phrase said gets the
/// noise rotated by `(k * noise_stride + noise_offset)` samples, so that
/// two corpora (the bench's, a tuning one) can use different stretches.
#[allow(clippy::too_many_arguments)]
pub fn walk_corpus(
    voices: &[String],
    rates: &[u32],
    snrs_db: &[Option<f64>],
    noise_stride: usize,
    noise_offset: usize,
    scratch: &Path,
    mut each: impl FnMut(CorpusUtterance<'_>) -> Result<()>,
) -> Result<()> {
    std::fs::create_dir_all(scratch).map_err(|e| {
        HilError::channel(
            "speech",
            format!("cannot create {}: {e}", scratch.display()),
        )
    })?;
    let items = corpus_items();
    let mut noise: Option<Audio> = None;
    let mut k = 0usize;
    for voice in voices {
        for &rate in rates {
            let v = EspeakVoice {
                voice: voice.clone(),
                rate,
            };
            for (grammar, phrase, meaning) in &items {
                let clean = crate::listener::say(&v, phrase, scratch)?;
                if noise.as_ref().is_none_or(|n| n.rate != clean.rate) {
                    noise = Some(sox_noise(&scratch.join("noise.wav"), clean.rate, 30)?);
                }
                let n = noise.as_ref().expect("made above");
                k += 1;
                for (snr_index, snr) in snrs_db.iter().enumerate() {
                    let audio = match snr {
                        None => clean.clone(),
                        Some(db) => {
                            // A different stretch of the noise each time.
                            let mut shifted = n.clone();
                            let len = shifted.samples.len();
                            shifted
                                .samples
                                .rotate_left((k * noise_stride + noise_offset) % len);
                            mix_at_snr(&clean, &shifted, *db)?
                        }
                    };
                    each(CorpusUtterance {
                        grammar,
                        phrase,
                        meaning: *meaning,
                        voice: &v,
                        snr_index,
                        audio,
                    })?;
                }
            }
        }
    }
    Ok(())
}

/// The bench's stretch of the noise: rotated by `k * 7919` samples.
pub const BENCH_NOISE_STRIDE: usize = 7919;

/// Runs the bench; `progress` is told each (done, total).
pub fn run(
    settings: &BenchSettings,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<BenchRow>> {
    settings.channel.validate()?;
    let mut recognizer = SphinxRecognizer::new(&settings.model_dir)?;
    let total = corpus_items().len()
        * settings.voices.len()
        * settings.rates.len()
        * settings.snrs_db.len();
    let mut per_snr: Vec<Vec<(bool, bool, bool, f64)>> = vec![Vec::new(); settings.snrs_db.len()];
    let mut done = 0;
    walk_corpus(
        &settings.voices,
        &settings.rates,
        &settings.snrs_db,
        BENCH_NOISE_STRIDE,
        0,
        &settings.scratch,
        |u| {
            let mut stream = MemoryStream::new(u.audio);
            let h = hear(&mut stream, &settings.channel, &mut recognizer, u.grammar)?;
            let said = h.recognition.as_ref().and_then(|r| r.meaning);
            let right = said == Some(u.meaning);
            let accepted = matches!(h.outcome, Outcome::Accepted | Outcome::Repeat);
            per_snr[u.snr_index].push((
                right,
                accepted && !right,
                !accepted,
                h.latency_ms.unwrap_or(f64::NAN),
            ));
            done += 1;
            progress(done, total);
            Ok(())
        },
    )?;
    let _ = std::fs::remove_dir_all(&settings.scratch);
    Ok(settings
        .snrs_db
        .iter()
        .zip(per_snr)
        .map(|(snr, rows)| {
            let n = rows.len().max(1) as f64;
            let frac = |f: fn(&(bool, bool, bool, f64)) -> bool| {
                rows.iter().filter(|r| f(r)).count() as f64 / n
            };
            let lat: Vec<f64> = rows.iter().map(|r| r.3).filter(|l| l.is_finite()).collect();
            BenchRow {
                snr_db: *snr,
                n: rows.len(),
                accuracy: frac(|r| r.0),
                false_accept: frac(|r| r.1),
                reask: frac(|r| r.2),
                latency_mean_ms: if lat.is_empty() {
                    f64::NAN
                } else {
                    lat.iter().sum::<f64>() / lat.len() as f64
                },
                latency_p95_ms: if lat.is_empty() {
                    f64::NAN
                } else {
                    hil_stats::quantile(&lat, 0.95)
                },
            }
        })
        .collect())
}

/// The rows as a table (the accuracy's binomial standard error beside it).
pub fn table(rows: &[BenchRow]) -> String {
    let mut out = String::from(
        "SNR      n     accuracy         false accepts  re-asks  latency mean  latency p95\n",
    );
    for r in rows {
        let snr = r
            .snr_db
            .map_or("clean".to_string(), |d| format!("{d:.0} dB"));
        let right = (r.accuracy * r.n as f64).round() as usize;
        let se = hil_stats::binomial_se(right, r.n);
        out.push_str(&format!(
            "{snr:<8} {:<5} {:>6.2}% ± {:>4.2}%  {:>12.2}%  {:>6.2}%  {:>9.0} ms  {:>8.0} ms\n",
            r.n,
            100.0 * r.accuracy,
            100.0 * se,
            100.0 * r.false_accept,
            100.0 * r.reask,
            r.latency_mean_ms,
            r.latency_p95_ms
        ));
    }
    out
}
