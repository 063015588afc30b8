"""A plain-text script placed on the recording it was read in: split into sentences, each sentence's span estimated
over the voiced audio by its share of the letters still to come and snapped to a pause near it (the longer the
likelier); the next sentence starts where it ended. Each sentence comes with its span's audio
(:class:`~gesturecast.realtime.words.aligner.SentenceAudio`), to be aligned there when its words cue something."""

from __future__ import annotations

import re

import numpy as np

from gesturecast.realtime.words.aligner import SentenceAudio
from gesturecast.realtime.words.voicing import SAMPLE_RATE, letters, pause_runs, voiced_span

SENTENCE_END = re.compile(r"(?<=[.!?…])[\"')\]]*\s+|\n\s*\n|\n(?=\s*[-*•])")  # after . ! ? …, a blank line, a bullet
MAX_SENTENCE_WORDS = 40  # a longer run without a sentence end is cut into pieces this long (alignment stays cheap)
SNAP_S = 1.5  # a sentence's end moves to a pause within this many seconds of its estimate
PAUSE_WEIGHT = 2.0  # seconds nearer the estimate that each second more of pause is worth
LONG_PAUSE_S = 1.0  # the end of the voiced audio counts as a pause this long


def sentences(text: str) -> list[str]:
    """The sentences of a script, each at most :data:`MAX_SENTENCE_WORDS` words, whitespace collapsed."""
    pieces = []
    for sentence in SENTENCE_END.split(text):
        tokens = sentence.split()
        pieces += [" ".join(tokens[i : i + MAX_SENTENCE_WORDS]) for i in range(0, len(tokens), MAX_SENTENCE_WORDS)]
    return pieces


def script_sentences(text: str, samples: np.ndarray) -> list[SentenceAudio]:
    """The sentences of ``text``, each with the audio of its span on ``samples`` ((n,) float32, 16 kHz, from stream
    time 0)."""
    parts = sentences(text)
    duration = len(samples) / SAMPLE_RATE
    span = voiced_span(samples) or (0.0, duration)
    runs = pause_runs(samples) + [(span[1], LONG_PAUSE_S)]
    breaks, lengths = np.array([middle for middle, _ in runs]), np.array([length for _, length in runs])
    cursor, placed = span[0], []
    weights = [sum(letters(token) for token in part.split()) for part in parts]
    remaining = sum(weights)  # letters from this sentence on
    for index, part in enumerate(parts):
        share = weights[index] / remaining if remaining else 1.0
        remaining -= weights[index]
        estimate = cursor + share * max(span[1] - cursor, 0.0)
        near = (breaks > cursor) & (np.abs(breaks - estimate) <= SNAP_S)
        score = np.abs(breaks - estimate) - PAUSE_WEIGHT * lengths  # a longer pause more likely ends a sentence
        end = float(breaks[near][np.argmin(score[near])]) if near.any() else estimate
        end = span[1] if index == len(parts) - 1 else max(end, cursor)
        placed.append(_with_audio(part, samples, cursor, end))
        cursor = end
    return placed


def _with_audio(text: str, samples: np.ndarray, start: float, end: float) -> SentenceAudio:
    """``text`` with the audio from ``start`` to ``end`` seconds."""
    first, last = int(start * SAMPLE_RATE), max(int(end * SAMPLE_RATE), int(start * SAMPLE_RATE))
    return SentenceAudio(text, samples[first:last], first / SAMPLE_RATE)
