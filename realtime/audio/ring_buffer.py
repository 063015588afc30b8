"""Bounded float32 ring buffer between the audio callback (producer) and the engine (consumer).

The producer only copies samples in (``write``), under a lock held for one or two ``memcpy``s.
When the consumer falls behind and the buffer is full, the **oldest** samples are overwritten:
the freshest audio matters for a live avatar. Every overwritten sample is counted
(``dropped_samples``) and every write that had to overwrite counts as one ``overruns`` event.
Samples keep absolute stream indices, so the consumer knows where a gap happened.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RingStats:
    written_samples: int
    dropped_samples: int
    overruns: int


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
        self._dropped = 0
        self._overruns = 0
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
            overflow = self._written - self._read - self.capacity
            if overflow > 0:
                self._dropped += overflow
                self._overruns += 1
                self._read += overflow
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
            return read

    @property
    def available(self) -> int:
        with self._ready:
            return self._written - self._read

    def stats(self) -> RingStats:
        with self._ready:
            return RingStats(self._written, self._dropped, self._overruns)
