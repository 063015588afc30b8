"""Absolute-indexed sample history for the streaming feature extractor (single thread).

Sample ``i`` of the stream (0 = first sample pushed) lives at ``data[i - start]``. The history
starts with ``pre_roll`` zeros at negative indices, so every analysis window — even the first
one — reads real memory and the stream behaves as if preceded by silence.
"""

from __future__ import annotations

import numpy as np

GROWTH_FACTOR = 2


class SampleHistory:
    def __init__(self, pre_roll: int, initial_capacity: int) -> None:
        self.pre_roll = pre_roll
        self._data = np.zeros(max(initial_capacity, 2 * pre_roll), np.float32)
        self.start = -pre_roll  # absolute index of data[0]
        self._fill = pre_roll  # the pre-roll zeros count as filled

    @property
    def end(self) -> int:
        """Absolute index one past the newest sample."""
        return self.start + self._fill

    def append(self, samples: np.ndarray) -> None:
        """Copy (n,) float32 samples in; amortised O(n), one slice assignment on the fast path."""
        needed = self._fill + samples.shape[0]
        if needed > self._data.shape[0]:
            grown = np.zeros(needed * GROWTH_FACTOR, np.float32)
            grown[: self._fill] = self._data[: self._fill]
            self._data = grown
        self._data[self._fill : needed] = samples
        self._fill = needed

    def window(self, abs_start: int, abs_end: int) -> np.ndarray:
        """View of samples [abs_start, abs_end); both must lie inside the kept history."""
        return self._data[abs_start - self.start : abs_end - self.start]

    def relative(self, absolute: np.ndarray) -> np.ndarray:
        """Absolute sample indices → indices into :meth:`array`."""
        return absolute - self.start

    def array(self) -> np.ndarray:
        return self._data[: self._fill]

    def keep_from(self, abs_start: int) -> None:
        """Forget samples before ``abs_start`` (moves the kept tail to the front)."""
        drop = abs_start - self.start
        if drop <= 0:
            return
        kept = self._fill - drop
        self._data[:kept] = self._data[drop : self._fill]
        self._fill = kept
        self.start = abs_start
