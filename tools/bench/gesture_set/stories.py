"""The spoken texts of ``gesturecast bench gestures``: espeak-ng audio with exact word times, and the intended cues.

Each sentence of :mod:`gesturecast.tools.bench.gesture_set.texts` is spoken on its own by espeak-ng through its library
(:mod:`gesturecast.tools.bench.speech.espeak_words`: every word's start from the synthesiser's own word events);
sentences are joined with :data:`PAUSE_S` of silence after :data:`LEAD_IN_S`. A word ends where the next begins
(the last one at its sentence's end). ``[mark]`` marks become :class:`Intended` cues: the intent the mark stands
for (:data:`~gesturecast.realtime.gestures.speech_acts.MARKS`) at the marked word's start.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.controls import Word
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.gestures.speech_acts import MARKS
from gesturecast.tools.bench.speech.espeak_words import spoken
from gesturecast.tools.gestures.speech_act_training import parse_marked

CACHE = Path(".cache/bench/gestures")
PAUSE_S = 0.5  # between sentences: cues in neighbouring sentences come close together
LEAD_IN_S = 1.5  # silence before the first sentence: room for a gesture whose stroke lands on the first word


@dataclass(frozen=True)
class Intended:
    intent: str
    time: float  # the marked word's start (stream s)
    word: str


@dataclass(frozen=True)
class Story:
    name: str
    audio: np.ndarray  # (n,) 16 kHz
    words: list[Word]
    intended: list[Intended]

    @property
    def minutes(self) -> float:
        return len(self.audio) / SAMPLE_RATE / 60


def make_story(name: str, sentences: tuple[str, ...], cache: Path = CACHE, voice: str | None = None) -> Story:
    """The sentences spoken one after another (module docstring) in the espeak-ng ``voice`` (None: its default)."""
    pieces, words, intended, start = [np.zeros(int(LEAD_IN_S * SAMPLE_RATE), np.float32)], [], [], LEAD_IN_S
    for sentence in sentences:
        tokens, marks = parse_marked(sentence)
        audio, timed = spoken(" ".join(tokens), cache, voice)
        duration = len(audio) / SAMPLE_RATE
        ends = [w.start for w in timed[1:]] + [duration]
        words += [Word(w.text, start + w.start, start + end) for w, end in zip(timed, ends, strict=True)]
        intended += [Intended(MARKS[mark], start + timed[index].start, timed[index].text)
                     for index, mark in sorted(marks.items())]
        pieces += [audio, np.zeros(int(PAUSE_S * SAMPLE_RATE), np.float32)]
        start += duration + PAUSE_S
    return Story(name, np.concatenate(pieces), words, intended)
