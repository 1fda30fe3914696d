//! Ctrl-C through `hil_speech::stop::stop_all` (what `hil run`'s interrupt
//! handler calls): the utterance being heard is finished and recorded, and
//! the channel stops before listening again. In a file of its own: the
//! flags are process-wide, and no other test's channel may be stopped.

use std::sync::{Arc, Mutex};

use hil_core::{Context, HilError, Item, Query, QueryChannel, QueryKind, Response, Result};
use hil_speech::audio::Audio;
use hil_speech::grammar::{Grammar, Meaning};
use hil_speech::recognize::{Recognition, Recognizer};
use hil_speech::source::{AudioSource, AudioStream, MemoryStream};
use hil_speech::tts::TranscriptVoice;
use hil_speech::{SpeechChannel, SpeechSettings};

/// A tone burst in silence: an utterance for the detector.
fn utterance() -> Audio {
    let mut samples = vec![0.0f32; 8000];
    samples.extend((0..16_000).map(|i| 0.3 * (i as f32 * 0.2).sin()));
    samples.extend(vec![0.0f32; 8000]);
    Audio {
        rate: 16_000,
        samples,
    }
}

/// A source whose person presses Ctrl-C while answering the first time
/// (the signal arrives during the utterance).
#[derive(Debug)]
struct CtrlCWhileAnswering {
    opened: Arc<Mutex<usize>>,
}

impl AudioSource for CtrlCWhileAnswering {
    fn open(&mut self, _q: &Query, _attempt: usize) -> Result<Box<dyn AudioStream>> {
        *self.opened.lock().unwrap() += 1;
        assert_eq!(hil_speech::stop::stop_all(), 1, "one live channel");
        Ok(Box::new(MemoryStream::new(utterance())))
    }
}

/// Hears nothing in the grammar: the channel would ask again.
#[derive(Debug)]
struct Unsure;

impl Recognizer for Unsure {
    fn recognize(&mut self, _g: &Grammar, _s: &[i16]) -> Result<Recognition> {
        Ok(Recognition {
            transcript: String::new(),
            meaning: None::<Meaning>,
            confidence: 0.0,
        })
    }
}

fn query() -> Query {
    Query::new(
        1,
        Item::new(0, "banana"),
        QueryKind::default(),
        hil_core::ActionSpace::new(["a", "b"]).unwrap(),
        Context::new(vec![0.0]).unwrap(),
    )
}

#[test]
fn ctrl_c_during_an_utterance_stops_the_channel_before_the_next_one() {
    let opened = Arc::new(Mutex::new(0));
    let voice = TranscriptVoice::default();
    let mut ch = SpeechChannel::new(
        Box::new(voice.clone()),
        Box::new(CtrlCWhileAnswering {
            opened: opened.clone(),
        }),
        Box::new(Unsure),
        SpeechSettings::default(),
    )
    .unwrap();
    let r: Result<Response> = ch.ask(&query());
    assert!(matches!(r, Err(HilError::Channel { .. })), "{r:?}");
    // The utterance under way was heard and kept; no second one was
    // listened for, and "say that again" was not said.
    assert_eq!(*opened.lock().unwrap(), 1);
    assert_eq!(ch.turns.len(), 1);
    assert_eq!(voice.said().len(), 1, "{:?}", voice.said());
    drop(ch);
    // A dropped channel is no longer stopped.
    assert_eq!(hil_speech::stop::stop_all(), 0);
}
