"""A buffer of normalised audio feature frames addressed by absolute frame index (constant memory)."""

from __future__ import annotations

import numpy as np

from gesturecast.models.generator.denoiser_config import DenoiserConfig, audio_window_bounds, audio_window_from_features


class FeatureBuffer:
    """Holds the frames not yet needed by any latent; :meth:`forget_before` drops the consumed ones.

    Frame indices are absolute (frame 0 = the first 1/30 s of the stream), so the audio window of
    latent ``i`` follows the same rule as in training (:func:`audio_window_from_features`). The
    session forgets every frame before the next latent's window, so memory stays bounded by one
    window plus one pushed chunk, however long the stream runs.
    """

    def __init__(self, num_features: int) -> None:
        self._frames = np.zeros((0, num_features), np.float32)  # (kept, F)
        self._speaking = np.zeros(0, bool)  # (kept,) voice-activity flag of each kept frame
        self._first = 0  # absolute index of self._frames[0]

    @property
    def end(self) -> int:
        """Absolute index one past the newest frame (= frames received so far)."""
        return self._first + len(self._frames)

    @property
    def kept(self) -> int:
        return len(self._frames)

    def append(self, frames: np.ndarray, speaking: np.ndarray) -> None:
        """(n, F) new normalised frames and their (n,) speaking flags."""
        self._frames = np.concatenate([self._frames, frames.astype(np.float32)])
        self._speaking = np.concatenate([self._speaking, speaking.astype(bool)])

    def forget_before(self, frame: int) -> None:
        """Drop frames with absolute index < ``frame``."""
        drop = min(max(frame - self._first, 0), len(self._frames))
        self._frames = self._frames[drop:]
        self._speaking = self._speaking[drop:]
        self._first += drop

    def window(self, latent_index: int, config: DenoiserConfig) -> np.ndarray:
        """The (A, F) audio window of one latent, zero-padded before frame 0, exactly as in training."""
        start, end = audio_window_bounds(latent_index, config)
        if max(start, 0) < self._first:
            raise ValueError(f"frames from {start} were already dropped (buffer starts at {self._first})")
        kept = self._frames[: end - self._first]  # absolute frames [first, end)
        if self._first == 0:
            return audio_window_from_features(kept, latent_index, config)
        return kept[start - self._first :]

    def last_speech(self, start: int, end: int) -> int | None:
        """Absolute index of the last speaking frame in [start, end), or None."""
        flags = np.flatnonzero(self._speaking[max(start - self._first, 0) : end - self._first])
        return None if flags.size == 0 else max(start, self._first) + int(flags[-1])
