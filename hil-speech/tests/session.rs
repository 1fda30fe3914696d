//! A full LinUCB-QG session on `food_replay`, answered aloud: a scripted
//! listener says the best action of every query (espeak-ng → WAV), the
//! channel hears it (resampling, endpointing, pocketsphinx) and the
//! session's record holds what the listener said.
#![cfg(feature = "engines")]

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use hil_core::session::EventCollector;
use hil_core::{Answer, ArmId, Query, ResponseType};
use hil_speech::channel::answer_for;
use hil_speech::grammar::{Grammar, Meaning};
use hil_speech::listener::ScriptedListener;
use hil_speech::recognize::SphinxRecognizer;
use hil_speech::tts::{EspeakVoice, TranscriptVoice};
use hil_speech::{SpeechChannel, SpeechSettings};

/// The project's LinUCB-QG config on `food_replay` (its `[channel]`, a
/// simulated expert, is replaced by the speech channel below).
fn config() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/configs/paper-test-linucb-qg.toml")
}

#[test]
#[ignore = "needs scripts/setup-speech"]
fn a_linucb_qg_session_answered_aloud_records_the_listeners_answers() {
    let dir = std::env::temp_dir().join(format!("hil-speech-session-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = config();
    let cfg = hil_experiments::load_experiment(&path).unwrap();
    let mut experiment = cfg.build(path.parent().unwrap()).unwrap();
    experiment.episodes = 1;
    // What the listener meant, per step.
    let meant: Arc<Mutex<Vec<(u64, Answer)>>> = Arc::default();
    let script = {
        let meant = meant.clone();
        Box::new(move |q: &Query, _attempt: usize| {
            let meaning = match q.kind.response {
                ResponseType::BoundingBox => Meaning::Region(4),
                _ => Meaning::Choice(q.oracle_best.unwrap_or(ArmId(0)).0),
            };
            let (answer, _) = answer_for(q, meaning).unwrap();
            let mut meant = meant.lock().unwrap();
            // Asked again: the same answer, said again.
            if meant.last().is_none_or(|(t, _)| *t != q.t) {
                meant.push((q.t, answer));
            }
            Grammar::for_query(q)
                .phrase_for(meaning)
                .map(str::to_string)
        })
    };
    let voice = EspeakVoice {
        voice: "en-gb".into(),
        rate: 150,
    };
    let listener = ScriptedListener::new(voice, dir.clone(), script);
    let recognizer =
        SphinxRecognizer::new(Path::new(hil_speech::recognize::DEFAULT_MODEL_DIR)).unwrap();
    let settings = SpeechSettings {
        audio_dir: Some(dir.join("audio")),
        ..Default::default()
    };
    experiment.channel = Box::new(
        SpeechChannel::new(
            Box::new(TranscriptVoice::default()),
            Box::new(listener),
            Box::new(recognizer),
            settings,
        )
        .unwrap(),
    );
    let mut events = EventCollector::default();
    experiment.run(&mut [&mut events], |_, _| {}).unwrap();
    let recorded: Vec<(u64, Answer)> = events
        .events
        .iter()
        .filter_map(|e| {
            e.step
                .response
                .as_ref()
                .map(|r| (e.step.t, r.answer.clone()))
        })
        .collect();
    let meant = meant.lock().unwrap().clone();
    assert!(!recorded.is_empty(), "the policy asked no query");
    assert_eq!(recorded, meant);
    std::fs::remove_dir_all(&dir).unwrap();
}
