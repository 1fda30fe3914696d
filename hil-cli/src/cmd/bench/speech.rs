//! `hil bench speech`: the spoken channel's recognition figures on a corpus
//! made at run time (the logic is `hil_speech::bench`; this file parses
//! and prints).

use hil_core::Result;

/// Arguments of `hil bench speech`.
#[derive(Debug, clap::Args)]
pub struct SpeechBench {
    /// espeak-ng voices (comma-separated; `espeak-ng --voices=en` lists them).
    #[arg(long, value_delimiter = ',', default_values_t = ["en-us".to_string(), "en-gb".into(), "en-us+f3".into(), "en-gb-scotland".into()])]
    voices: Vec<String>,
    /// Speaking rates, words per minute (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [130u32, 160, 200])]
    rates: Vec<u32>,
    /// Least confidence taken as an answer.
    #[arg(long, default_value_t = 0.5)]
    threshold: f64,
    /// Print the rows as JSON.
    #[arg(long)]
    json: bool,
    /// Also keep the printed table as a Markdown results page at this path
    /// (e.g. docs/results/speech-bench.md), naming this command line.
    #[arg(long, value_name = "FILE", conflicts_with = "json")]
    write_doc: Option<std::path::PathBuf>,
}

#[cfg(feature = "speech")]
pub fn run(a: &SpeechBench) -> Result<()> {
    use hil_speech::bench;
    let mut settings = bench::BenchSettings {
        voices: a.voices.clone(),
        rates: a.rates.clone(),
        ..Default::default()
    };
    settings.channel.threshold = a.threshold;
    let rows = bench::run(&settings, |done, total| {
        if done % 100 == 0 || done == total {
            crate::out::stderr(format_args!("\rheard {done}/{total} utterances"));
        }
    })?;
    crate::out::note!();
    if a.json {
        crate::out::outln!(
            "{}",
            serde_json::to_string_pretty(&rows)
                .map_err(|e| hil_core::HilError::serde("bench rows", e))?
        )?;
    } else {
        let report = format!(
            "corpus: every answer of every query kind, espeak-ng voices {} at {} wpm, pink noise (sox); threshold {}\n{}",
            a.voices.join(", "),
            a.rates
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join("/"),
            a.threshold,
            bench::table(&rows)
        );
        crate::cmd::emit_report(
            &report,
            a.write_doc.as_deref(),
            "Spoken answers: recognition on a synthetic corpus",
        )?;
    }
    Ok(())
}

#[cfg(not(feature = "speech"))]
pub fn run(_a: &SpeechBench) -> Result<()> {
    Err(crate::speech_unavailable::error())
}
