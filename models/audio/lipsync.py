"""Viseme weights (a i u e o) per motion frame, causally, from the frame's own audio (docs/lipsync.md).

Per frame k (the samples up to its end b(k + 1), the same instant the frame's speech features describe):

1. **Mouth opening** ``o_k`` from the frame's RMS level (the ``energy`` feature, dBFS): 0 at
   ``closed_db`` and below, 1 at ``open_db`` and above, linear in dB between; 0 whenever the
   voice-activity flag is off (silence gives exactly zero weights).
2. **Mouth shape** ``p_k`` (5 probabilities) from the first two formants (:mod:`formants`): the log
   distance ``d_v = min_s ‖log F − log s − log R_v‖`` to each vowel's reference formants ``R_v``, with
   vocal-tract scales ``s`` that cover men, women and children, and ``p_v ∝ exp(−d_v² / 2σ²)``. Where
   no two formants are found (stops, fricatives) the previous shape is held.
3. **Weights** ``w_k = α w_{k−1} + (1 − α) o_k p_k`` (one-pole smoothing against frame-to-frame
   flicker; it delays by α/(1 − α) of a frame). Their sum is the mouth opening (≤ 1).

Every step is a per-frame function or a frame-by-frame recurrence, so the weights do not depend on how
the audio was chunked (the extractor's streaming = offline parity holds for them too).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gesturecast.frames import VISEME_VOWELS
from gesturecast.models.audio.formants import FormantConfig, FormantTracker

# (F1, F2) in Hz of an adult male voice, five-vowel system (approximate textbook values for Spanish and
# Japanese vowels; VRM's A I U E O are the Japanese ones). Order = VISEME_VOWELS.
REFERENCE_FORMANTS_HZ = np.array([
    [730.0, 1300.0],  # a
    [290.0, 2250.0],  # i
    [330.0, 800.0],  # u
    [460.0, 1900.0],  # e
    [480.0, 900.0],  # o
])
VOCAL_TRACT_SCALES = (1.0, 1.1, 1.2)  # formants scale with 1 / vocal-tract length: men, women, children
SILENT_MOUTH = 0.1  # mouth opening (sum of weights) below which a frame counts as closed / silent


@dataclass(frozen=True)
class LipSyncConfig:
    closed_db: float = -50.0  # frame RMS (dBFS) at which the mouth is shut (the VAD's absolute floor)
    open_db: float = -20.0  # … and fully open
    shape_sigma: float = 0.15  # σ of the shape softmax, in natural-log formant units (≈ 15 %)
    smoothing: float = 0.3  # α of the one-pole smoothing (0: off)
    formants: FormantConfig = field(default_factory=FormantConfig)


class LipSync:
    """Streaming viseme weights; call :meth:`update` with each burst of frames in stream order."""

    def __init__(self, config: LipSyncConfig | None = None) -> None:
        self.config = config or LipSyncConfig()
        self.tracker = FormantTracker(self.config.formants)
        scales = np.log(np.asarray(VOCAL_TRACT_SCALES))[:, None, None]  # (S, 1, 1)
        self._log_references = np.log(REFERENCE_FORMANTS_HZ)[None] + scales  # (S, V, 2)
        self.reset()

    def reset(self) -> None:
        self._shape = np.full(len(VISEME_VOWELS), 1.0 / len(VISEME_VOWELS))  # (V,) held shape
        self._weights = np.zeros(len(VISEME_VOWELS))  # (V,) previous output

    def update(self, windows: np.ndarray, energy_db: np.ndarray, speaking: np.ndarray) -> np.ndarray:
        """(T, N) sample windows ending at each frame's end, (T,) RMS dBFS, (T,) speaking → (T, 5) float32."""
        formants = self.tracker.track(windows)  # (T, 2)
        shapes = self.shape(formants)  # (T, V), NaN rows where no formants were found
        opening = self.opening(np.asarray(energy_db, np.float64), np.asarray(speaking) > 0)  # (T,)
        out = np.zeros((len(formants), len(VISEME_VOWELS)), np.float32)
        alpha = self.config.smoothing
        for k, (shape, open_k) in enumerate(zip(shapes, opening, strict=True)):
            if np.isfinite(shape).all():
                self._shape = shape
            self._weights = alpha * self._weights + (1.0 - alpha) * open_k * self._shape
            out[k] = self._weights
        return out

    def opening(self, energy_db: np.ndarray, speaking: np.ndarray) -> np.ndarray:
        """(T,) dBFS and (T,) bool → (T,) mouth opening in [0, 1]."""
        cfg = self.config
        level = np.clip((energy_db - cfg.closed_db) / (cfg.open_db - cfg.closed_db), 0.0, 1.0)
        return np.where(speaking, level, 0.0)

    def shape(self, formants_hz: np.ndarray) -> np.ndarray:
        """(T, 2) F1, F2 in Hz → (T, 5) vowel probabilities (scale-normalised nearest-template softmax)."""
        offsets = np.log(formants_hz)[:, None, None] - self._log_references[None]  # (T, S, V, 2)
        distance = np.linalg.norm(offsets, axis=-1).min(axis=1)  # (T, V)
        logits = -0.5 * (distance / self.config.shape_sigma) ** 2
        probabilities = np.exp(logits - logits.max(axis=1, keepdims=True))
        return probabilities / probabilities.sum(axis=1, keepdims=True)


def mouth_class(weights: np.ndarray) -> np.ndarray:
    """(T, 5) weights → (T,) class: 0-4 = the vowel of VISEME_VOWELS, 5 = closed (opening < SILENT_MOUTH)."""
    vowel = np.argmax(weights, axis=-1)
    return np.where(weights.sum(axis=-1) < SILENT_MOUTH, len(VISEME_VOWELS), vowel)
