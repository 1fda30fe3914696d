//! One turn of listening, the same for every source: resample the
//! source's chunks to 16 kHz as they come, find the utterance, stop at the
//! timeout.

use hil_core::Result;

use crate::audio::{RECOGNIZER_RATE, resample};
use crate::endpoint::{EndpointSettings, Endpointer, Utterance};
use crate::source::AudioStream;

/// What a turn heard.
#[derive(Clone, Debug, PartialEq)]
pub enum Heard {
    /// An utterance.
    Utterance(Utterance),
    /// No speech started within the timeout (or before the stream ended).
    Nothing {
        /// Seconds of audio listened to.
        listened_s: f64,
    },
}

/// Listens to `stream` for at most `timeout_s` seconds of audio before
/// speech starts (an utterance that has started is heard to its end).
pub fn listen(
    stream: &mut dyn AudioStream,
    settings: EndpointSettings,
    timeout_s: f64,
) -> Result<Heard> {
    let rate = stream.rate();
    let mut ep = Endpointer::new(settings);
    // Resampling chunk by chunk would put seams at every boundary; a
    // microphone's chunks are resampled in blocks of 0.5 s instead.
    let block = (rate / 2) as usize;
    let mut pending: Vec<f32> = Vec::new();
    let feed = |ep: &mut Endpointer, samples: &[f32]| {
        let converted = resample(samples, rate, RECOGNIZER_RATE);
        ep.push(&converted)
    };
    loop {
        if !ep.in_speech() && ep.seconds() >= timeout_s {
            return Ok(Heard::Nothing {
                listened_s: ep.seconds(),
            });
        }
        match stream.next_chunk()? {
            Some(chunk) => {
                if rate == RECOGNIZER_RATE {
                    if let Some(u) = ep.push(&chunk) {
                        return Ok(Heard::Utterance(u));
                    }
                } else {
                    pending.extend_from_slice(&chunk);
                    if pending.len() >= block
                        && let Some(u) = feed(&mut ep, &std::mem::take(&mut pending))
                    {
                        return Ok(Heard::Utterance(u));
                    }
                }
            }
            None => {
                if !pending.is_empty()
                    && let Some(u) = feed(&mut ep, &std::mem::take(&mut pending))
                {
                    return Ok(Heard::Utterance(u));
                }
                return Ok(match ep.finish() {
                    Some(u) => Heard::Utterance(u),
                    None => Heard::Nothing {
                        listened_s: ep.seconds(),
                    },
                });
            }
        }
    }
}
