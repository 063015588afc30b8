"""Voiced and unvoiced stretches of 16 kHz mono audio by frame energy, and words spread over a span by their letters:
what places a sentence when its forced alignment cannot."""

from __future__ import annotations

import numpy as np

from gesturecast.controls import Word

SAMPLE_RATE = 16_000
FRAME_S = 0.01  # one energy frame, as the aligner's own frames
FRAME = int(SAMPLE_RATE * FRAME_S)
FLOOR_RMS = 0.003  # about -50 dBFS: quieter than any speech frame
NOISE_FACTOR = 4.0  # a frame is voiced above this many times the audio's quiet frames (its 10th-percentile RMS)
MIN_PAUSE_S = 0.15  # an unvoiced run this long separates sentences


def frame_rms(samples: np.ndarray) -> np.ndarray:
    """(n,) float32 samples → (n // FRAME,) RMS of each 10 ms frame."""
    frames = samples[: len(samples) // FRAME * FRAME].reshape(-1, FRAME)  # (F, 160)
    return np.sqrt(np.mean(np.square(frames, dtype=np.float64), axis=1))


def voiced_frames(samples: np.ndarray, context: np.ndarray | None = None) -> np.ndarray:
    """(F,) bool: the 10 ms frames louder than the quiet frames of ``context`` (default: ``samples`` itself; a
    longer stretch around them when they may all be speech) and than :data:`FLOOR_RMS`."""
    rms = frame_rms(samples)
    quiet = frame_rms(samples if context is None else context)
    if not len(rms) or not len(quiet):
        return np.zeros(len(rms), bool)
    return rms > max(FLOOR_RMS, NOISE_FACTOR * float(np.percentile(quiet, 10)))


def voiced_span(samples: np.ndarray) -> tuple[float, float] | None:
    """(first, last) second of voiced audio in ``samples`` (None when none is voiced)."""
    voiced = np.flatnonzero(voiced_frames(samples))
    if not len(voiced):
        return None
    return float(voiced[0] * FRAME_S), float((voiced[-1] + 1) * FRAME_S)


def pauses(samples: np.ndarray, min_pause_s: float = MIN_PAUSE_S) -> list[float]:
    """The middle second of each unvoiced run at least ``min_pause_s`` long that follows voiced audio (a run still
    going at the end counts: the speech may have stopped there)."""
    return [middle for middle, _ in pause_runs(samples, min_pause_s)]


def pause_runs(samples: np.ndarray, min_pause_s: float = MIN_PAUSE_S, context: np.ndarray | None = None
               ) -> list[tuple[float, float]]:
    """(middle second, length in seconds) of each pause :func:`pauses` finds (voicing judged against ``context``,
    as :func:`voiced_frames`)."""
    voiced = np.concatenate([voiced_frames(samples, context), [True]])  # (F + 1,) a voiced frame closes the last run
    changes = np.flatnonzero(np.diff(voiced.astype(np.int8)))  # the last frame before each change
    starts, ends = changes[voiced[changes]] + 1, changes[~voiced[changes]] + 1  # first unvoiced, first voiced again
    return [(float((start + end) / 2 * FRAME_S), float((end - start) * FRAME_S))
            for start, end in zip(starts, ends[np.searchsorted(ends, starts)], strict=True)
            if (end - start) * FRAME_S >= min_pause_s]


def letters(token: str) -> int:
    """A token's share of speaking time: its letters and digits, plus one for the gap after it."""
    return sum(char.isalnum() for char in token) + 1


def end_by_letters(tokens: list[str], count: int, span: tuple[float, float]) -> float:
    """Where the first ``count`` of ``tokens`` end when all of them fill ``span`` (seconds) by their letters."""
    share = sum(letters(token) for token in tokens[:count]) / sum(letters(token) for token in tokens)
    return span[0] + share * (span[1] - span[0])


def spread(tokens: list[str], start: float, end: float) -> list[Word]:
    """``tokens`` over ``start``..``end`` seconds, each a share of the span by its letters."""
    weights = np.array([letters(token) for token in tokens], np.float64)
    edges = start + (end - start) * np.concatenate([[0.0], np.cumsum(weights)]) / weights.sum()
    return [Word(token, float(edges[i]), float(edges[i + 1])) for i, token in enumerate(tokens)]
