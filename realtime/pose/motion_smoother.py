"""Streaming smoothing of the generated motion features: a centred binomial window, k frames of delay.

The generator emits d motion frames per latent frame; where two latents meet, the decoded motion
steps, which shows as jitter (generated jerk ≈ 3.4× real motion's). A centred window of 2k + 1
frames with binomial weights C(2k, i) / 4^k (the k-th power of [1, 2, 1] / 4, a discrete Gaussian
of variance k / 2 frames²) removes that step while passing gesture frequencies almost unchanged:
its gain is cos^(2k)(π f / fps), e.g. k = 2 at 30 fps keeps 2 Hz at 0.92 and 7.5 Hz (the latent
rate) at 0.25, and fully removes 15 Hz.

The window is centred, so frame t leaves once frame t + k exists: k frames (k / fps seconds) are
added to the latency budget (``LatencyBudget.smoothing_frames``). At the stream's start and end
the weights of missing neighbours are dropped and the rest renormalised. Features are smoothed
linearly (root channels and 6D rotations; the 6D → rotation step re-orthonormalises). The same
code runs for live and offline, so both stay identical; k = 0 passes frames through unchanged.
"""

from __future__ import annotations

from math import comb

import numpy as np


def binomial_weights(half_width: int) -> np.ndarray:
    """(2k + 1,) weights C(2k, i) / 4^k, summing to 1."""
    weights = np.array([comb(2 * half_width, i) for i in range(2 * half_width + 1)], dtype=np.float64)
    return weights / weights.sum()


class MotionSmoother:
    """Feature frames in (any count per push), smoothed frames out k frames later, in order."""

    def __init__(self, half_width: int) -> None:
        if half_width < 0:
            raise ValueError(f"smoothing half-width must be 0 or more frames, got {half_width}")
        self.half_width = half_width
        self.weights = binomial_weights(half_width)  # (2k + 1,)
        self.reset()

    def reset(self) -> None:
        self._frames: list[np.ndarray] = []  # the last k emitted frames (context), then the pending ones
        self._context = 0  # how many of _frames are already emitted

    def push(self, features: np.ndarray) -> np.ndarray:
        """Frames (n, D) in; the frames whose k future neighbours have now arrived out, smoothed (m, D)."""
        if self.half_width == 0:
            return features
        self._frames.extend(np.asarray(features, dtype=np.float64))
        ready = len(self._frames) - self._context - self.half_width
        return self._emit(max(ready, 0), features.shape[-1])

    def flush(self, feature_dim: int) -> np.ndarray:
        """End of stream: every pending frame, smoothed with the neighbours that exist (m, D)."""
        if self.half_width == 0:
            return np.zeros((0, feature_dim))
        return self._emit(len(self._frames) - self._context, feature_dim)

    def _emit(self, count: int, feature_dim: int) -> np.ndarray:
        out = np.empty((count, feature_dim))
        for row in range(count):
            out[row] = self._smoothed(self._context + row)
        self._context += count
        drop = max(self._context - self.half_width, 0)  # keep k frames of past context
        del self._frames[:drop]
        self._context -= drop
        return out

    def _smoothed(self, index: int) -> np.ndarray:
        """The weighted mean of frame ``index``'s neighbours within the window that exist (D,)."""
        k = self.half_width
        first, last = max(index - k, 0), min(index + k, len(self._frames) - 1)
        weights = self.weights[first - index + k: last - index + k + 1]  # (n,)
        window = np.stack(self._frames[first: last + 1])  # (n, D)
        return weights @ window / weights.sum()
