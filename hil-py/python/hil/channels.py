"""Query channels: who answers the robot's questions.

Every channel type hil knows is built with ``hil.QueryChannel(type,
environment=..., **params)`` (the ``[channel]`` table of a config, as
keyword arguments). This module names the ones with more to say:

- :func:`speech`: the robot asks aloud (espeak-ng) and hears the answer
  offline (pocketsphinx, restricted to the query's answers). It needs a
  build with the ``speech`` feature (``scripts/setup-speech``, then
  ``maturin develop --features speech``); :data:`SPEECH` says whether this
  build has it. Without it, building the channel raises ``ChannelError``
  saying how to get it.
"""

from __future__ import annotations

from os import PathLike
from typing import Any, Optional, Sequence, Union

from ._hil import SPEECH, QueryChannel

__all__ = ["SPEECH", "speech"]

_Path = Union[str, "PathLike[str]"]


def speech(
    *,
    replay: Optional[Sequence[_Path]] = None,
    audio_dir: Optional[_Path] = None,
    **params: Any,
) -> QueryChannel:
    """The spoken query channel (``[channel] type = "speech"``).

    Args:
        replay: WAV files answering in turn instead of the microphone (a
            recorded session, a test); prompts are then not played.
        audio_dir: where each utterance's WAV and JSON (transcript,
            confidence, timing) are kept.
        **params: the task (``environment=``, or ``actions=`` and ``dim=``)
            and the rest of the channel's table: ``device``,
            ``output_device``, ``voice={"voice": "en-us", "rate": 160}``,
            ``threshold`` (least confidence taken as an answer, default
            0.5), ``max_reasks``, ``timeout_s``, ``keep_audio``,
            ``denoise`` (the noise filter before the recognizer, default
            True),
            ``model_dir``, ``fallback={"type": "terminal"}``
            (hil-speech's README describes each).
    """
    if replay is not None:
        params["replay"] = [str(p) for p in replay]
    if audio_dir is not None:
        params["audio_dir"] = str(audio_dir)
    return QueryChannel("speech", **params)
