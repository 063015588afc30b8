"""Speaker / channel normalisation of the dB features: a causal, speech-gated running mean is subtracted.

The mean log-mel spectrum and level of a voice (and of the microphone and room) say who speaks and
how loud the channel is, not when to gesture. Subtracting their running average — cepstral mean
normalisation (Atal 1974) applied to the log-mel bands and the RMS energy, updated only on frames
flagged as speech — leaves the prosody (rises, stresses, pauses relative to *this* voice), so voices
the model never heard look more like the two it was trained on. The mean is an exponential moving
average with time constant ``time_constant_s`` over speech frames; before the first speech frame it
is a fixed prior level. With ``warm_start`` the mean is instead the plain average of the speech frames
heard so far until ``time_constant_s`` of speech has been heard (the EMA's weight is never below 1/n after
n speech frames): a new voice is normalised from its first words on, not after a few seconds of speech
pulled from the prior. Frame-by-frame recurrence: the result does not depend on the chunking.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PRIOR_LEVEL_DB = -45.0  # the running mean before any speech: a typical speech level in dBFS


@dataclass(frozen=True)
class SpeakerNormConfig:
    enabled: bool = False
    time_constant_s: float = 3.0  # the mean follows a voice (or a gain change) within a few seconds of speech
    warm_start: bool = False  # the mean of the speech so far (not the prior) until time_constant_s of speech

    def __post_init__(self) -> None:
        if self.time_constant_s <= 0:
            raise ValueError(f"time_constant_s must be positive, got {self.time_constant_s}")


class SpeakerNormalizer:
    """Subtracts the speech-gated running mean from (T, W) dB columns, one frame after another."""

    def __init__(self, width: int, config: SpeakerNormConfig, fps: float) -> None:
        self.width = width
        self.rate = 1.0 / (config.time_constant_s * fps)  # EMA weight of one speech frame
        self.warm_start = config.warm_start
        self.reset()

    def reset(self) -> None:
        self.mean = np.full(self.width, PRIOR_LEVEL_DB)  # (W,)
        self.speech_frames = 0

    def update(self, values_db: np.ndarray, speaking: np.ndarray) -> np.ndarray:
        """values_db (T, W), speaking (T,) in {0, 1} → (T, W) values minus the mean including frame t."""
        normalised = np.empty_like(values_db, dtype=np.float64)  # (T, W)
        for t, (row, speech) in enumerate(zip(values_db, speaking, strict=True)):
            if speech:
                self.speech_frames += 1
                rate = max(self.rate, 1.0 / self.speech_frames) if self.warm_start else self.rate
                self.mean = self.mean + rate * (row - self.mean)
            normalised[t] = row - self.mean
        return normalised
