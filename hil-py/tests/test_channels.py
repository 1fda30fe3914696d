"""hil.channels: the spoken query channel from Python.

The answers are WAV files espeak-ng says (the channel's replay source:
the same path as a microphone's audio after capture); they need a build
with the `speech` feature and scripts/setup-speech's engines.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import wave

import pytest

import hil
from conftest import TEST_FOODS

needs_speech = pytest.mark.skipif(
    not hil.channels.SPEECH or shutil.which("espeak-ng") is None,
    reason="needs a hil-py built with --features speech and scripts/setup-speech "
    "(espeak-ng, pocketsphinx)",
)


def spoken(path, phrase):
    """`phrase` said by espeak-ng into `path`, with 0.4 s of silence before
    and 0.8 s after (a person does not answer on the prompt's last sample)."""
    raw = path.with_suffix(".raw.wav")
    subprocess.run(["espeak-ng", "-v", "en-us", "-s", "160", "-w", str(raw), "--", phrase], check=True)
    with wave.open(str(raw)) as r:
        params, frames = r.getparams(), r.readframes(r.getnframes())
    width = params.sampwidth * params.nchannels
    with wave.open(str(path), "wb") as w:
        w.setparams(params)
        w.writeframes(b"\0" * int(0.4 * params.framerate) * width + frames + b"\0" * int(0.8 * params.framerate) * width)
    return path


@needs_speech
def test_a_spoken_answer_is_the_sessions_answer_and_is_kept(tmp_path):
    env = hil.Environment("food_replay", foods=TEST_FOODS, items_per_episode=1)
    answers = [spoken(tmp_path / f"a{i}.wav", "option two") for i in range(10)]
    channel = hil.channels.speech(environment=env, replay=answers, audio_dir=tmp_path / "audio", max_reasks=0)
    assert channel.name == "speech"
    log = tmp_path / "s.jsonl"
    hil.run_session(
        environment=env,
        policy=hil.AlwaysQuery(environment=env),
        workload="f1_sim",
        channel=channel,
        log=log,
        seed=3,
    )
    records = [json.loads(line) for line in log.read_text().splitlines()]
    steps = [r["step"] for r in records if r.get("record") == "step"]
    arms = [s["response"]["expert_arm"] for s in steps if s.get("response")]
    assert arms and all(a == 1 for a in arms), arms
    # Each utterance: its WAV and its transcript.
    turn = json.loads((tmp_path / "audio" / "step-1-turn-0.json").read_text())
    assert turn["recognition"]["transcript"] == "option two"
    assert (tmp_path / "audio" / "step-1-turn-0.wav").exists()


def test_a_build_without_speech_says_how_to_get_it():
    if hil.channels.SPEECH:
        pytest.skip("this build has speech")
    env = hil.Environment("food_replay", foods=TEST_FOODS)
    with pytest.raises(hil.ChannelError, match="--features speech"):
        hil.channels.speech(environment=env, replay=[])


def test_a_bad_setting_names_its_field():
    env = hil.Environment("food_replay", foods=TEST_FOODS)
    with pytest.raises(hil.InvalidInputError) as e:
        hil.channels.speech(environment=env, threshold=1.5)
    assert "threshold" in str(e.value)
