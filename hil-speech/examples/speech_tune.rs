//! The data the recognizer's confidence was tuned on, kept apart from
//! `hil bench speech`'s corpus: other espeak-ng voices, other speaking
//! rates and another stretch of the noise. Prints one JSON line per
//! utterance with how the recognizer weighed it (live and whole-utterance
//! decodings agree? margin over the best answer of another meaning), from
//! which `HALF_CONFIDENCE_MARGIN` was chosen; the bench then reports on its
//! own corpus.
//!
//! ```sh
//! cargo run --release -p hil-speech --features engines --example speech_tune -- \
//!     en-gb-x-rp,en-029,en-us-nyc,en-gb-x-gbclan 145,180 > tune.jsonl
//! ```

use hil_speech::SpeechSettings;
use hil_speech::bench::walk_corpus;
use hil_speech::channel::recognizer_input;
use hil_speech::listen::{Heard, listen};
use hil_speech::recognize::{DEFAULT_MODEL_DIR, SphinxRecognizer};
use hil_speech::source::MemoryStream;

fn list<T: std::str::FromStr>(arg: Option<String>, what: &str) -> Vec<T> {
    let Some(arg) = arg else {
        eprintln!("usage: speech_tune VOICES RATES (comma-separated); missing {what}");
        std::process::exit(2);
    };
    arg.split(',')
        .map(|x| {
            x.parse().unwrap_or_else(|_| {
                eprintln!("speech_tune: `{x}` is not one of the {what}");
                std::process::exit(2)
            })
        })
        .collect()
}

fn main() -> hil_core::Result<()> {
    let mut args = std::env::args().skip(1);
    let voices: Vec<String> = list(args.next(), "voices");
    let rates: Vec<u32> = list(args.next(), "rates");
    let mut recognizer = SphinxRecognizer::new(DEFAULT_MODEL_DIR.as_ref())?;
    let scratch = std::env::temp_dir().join(format!("hil-speech-tune-{}", std::process::id()));
    let settings = SpeechSettings::default();
    let snrs = [None, Some(20.0), Some(10.0), Some(5.0)];
    // Another stretch of the noise than the bench's (BENCH_NOISE_STRIDE).
    walk_corpus(&voices, &rates, &snrs, 104_729, 5003, &scratch, |u| {
        let (voice, rate, snr) = (&u.voice.voice, u.voice.rate, snrs[u.snr_index]);
        let (phrase, truth) = (u.phrase, u.meaning);
        let mut stream = MemoryStream::new(u.audio);
        let line = match listen(&mut stream, settings.endpoint, settings.timeout_s)? {
            Heard::Nothing { .. } => serde_json::json!({
                "voice": voice, "rate": rate, "phrase": phrase, "snr": snr,
                "truth": truth, "heard": false,
            }),
            Heard::Utterance(heard) => {
                let t = std::time::Instant::now();
                let samples = recognizer_input(&heard, &settings)?;
                let w = recognizer.weigh(u.grammar, &samples)?;
                serde_json::json!({
                    "voice": voice, "rate": rate, "phrase": phrase, "snr": snr,
                    "truth": truth, "heard": true, "transcript": w.transcript,
                    "meaning": w.meaning, "agree": w.agree,
                    "margin": if w.margin.is_finite() { w.margin } else { 1e9 },
                    "ms": t.elapsed().as_secs_f64() * 1000.0,
                })
            }
        };
        println!("{line}");
        Ok(())
    })?;
    let _ = std::fs::remove_dir_all(&scratch);
    Ok(())
}
