"""Bounded float32 ring buffer between the audio callback (producer) and the engine (consumer).

The producer only copies samples in (``write``), under a lock held for one or two ``memcpy``s. Nothing is
lost silently: the consumer may :meth:`RingBuffer.skip` unread samples on purpose (it fell so far behind that
they can no longer be answered in time), and a write into a full ring skips the oldest samples the same way
(a ring sized for the worst hiccup never needs to). Every skipped sample is counted (``skipped_samples``), and
each skip is one ``skips`` event, so ``written = read + skipped + available`` at every moment. Samples keep
absolute stream indices, so the consumer knows where a skip happened.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RingStats:
    written_samples: int
    read_samples: int
    skipped_samples: int  # unread samples passed over (consumer skip-ahead or a write into a full ring)
    skips: int  # skip events (each skip or overfull write counts once)


@dataclass(frozen=True)
class RingRead:
    samples: np.ndarray  # (n,) float32, a copy
    start_index: int  # absolute index of samples[0] in the producer's stream
    write_time: float  # producer's timestamp for the sample at ``time_index``
    time_index: int


class RingBuffer:
    def __init__(self, capacity: int) -> None:
        if capacity <= 0:
            raise ValueError(f"ring buffer capacity must be positive, got {capacity}")
        self.capacity = capacity
        self._data = np.zeros(capacity, np.float32)
        self._written = 0  # absolute index one past the newest sample
        self._read = 0  # absolute index of the oldest unread sample
        self._consumed = 0  # samples handed to the consumer
        self._skipped = 0
        self._skips = 0
        self._anchor = (0, 0.0)  # (absolute sample index, producer clock time) of the last write
        self._ready = threading.Condition(threading.Lock())

    def write(self, samples: np.ndarray, timestamp: float) -> None:
        """Producer side: copy (n,) samples in; ``timestamp`` is the capture time of samples[0]."""
        count = samples.shape[0]
        with self._ready:
            tail = samples[-self.capacity :] if count > self.capacity else samples
            start = (self._written + count - tail.shape[0]) % self.capacity
            first = min(tail.shape[0], self.capacity - start)
            self._data[start : start + first] = tail[:first]
            self._data[: tail.shape[0] - first] = tail[first:]
            self._anchor = (self._written, timestamp)
            self._written += count
            self._skip_locked(self._written - self._read - self.capacity)
            self._ready.notify()

    def read(self, max_samples: int, timeout: float | None = None) -> RingRead:
        """Consumer side: up to ``max_samples`` oldest unread samples; waits up to ``timeout`` for any."""
        with self._ready:
            if self._written == self._read and timeout:
                self._ready.wait(timeout)
            count = min(max_samples, self._written - self._read)
            start = self._read % self.capacity
            indices = (start + np.arange(count)) % self.capacity
            samples = self._data[indices]
            read = RingRead(samples, self._read, self._anchor[1], self._anchor[0])
            self._read += count
            self._consumed += count
            return read

    def skip(self, count: int) -> int:
        """Consumer side: pass over up to ``count`` oldest unread samples on purpose; returns how many."""
        with self._ready:
            skipped = min(count, self._written - self._read)
            self._skip_locked(skipped)
            return max(skipped, 0)

    def skip_behind(self, limit: int, keep: int) -> int:
        """Consumer side: when more than ``limit`` samples wait unread, skip all but the newest ``keep``; returns how
        many were skipped (0 when the backlog is within the limit)."""
        backlog = self.available  # a write in between only adds to the newest: the oldest skipped are still old
        return self.skip(backlog - keep) if backlog > limit else 0

    def _skip_locked(self, count: int) -> None:
        if count > 0:
            self._read += count
            self._skipped += count
            self._skips += 1

    @property
    def available(self) -> int:
        with self._ready:
            return self._written - self._read

    def stats(self) -> RingStats:
        with self._ready:
            return RingStats(self._written, self._consumed, self._skipped, self._skips)
