"""The fixed latency budget L and bounded-memory rolling latency statistics.

L is what the user sets their audio delay to. A pose frame answering audio captured at time c is
presented at c + L, where (GestureDiffuCLIP streaming, one step per latent frame):

    L = (d + δa + k) / fps  +  compute margin

d motion frames make one latent frame: its first pose frame can be generated only once the audio up to
the end of the latent frame (d frames) plus δa look-ahead frames has arrived; a pose frame then waits
for the k motion frames after it (the centred smoothing window, realtime/pose/motion_smoother.py); the
margin covers compute, audio block size and sending.

``--latency low|balanced|quality`` picks a look-ahead and a margin (:data:`gesturecast.settings.LATENCY_SETTINGS`;
the measurements behind the margins are in docs/latency.md "Latency settings"). Look-aheads shorter than
the model's δa need a model trained with look-ahead truncation.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError
from gesturecast.realtime.timing.clock import Clock

MOTION_FPS = 30.0
MS_PER_S = 1000.0
DEFAULT_WINDOW = 1 << 16  # samples kept per stage: ~36 minutes of 30 fps frames, 512 KiB
INITIAL_RING_SAMPLES = 1 << 9  # a stage's ring starts at 4 KiB and doubles up to the window
SUMMARY_PERCENTILES = (50.0, 95.0, 99.0)


_charged = threading.local()  # per thread: CPU seconds other threads spent on its behalf


def charge_cpu(seconds: float) -> None:
    """Count ``seconds`` of CPU that another thread spent for the calling thread (its share of a batched call, as
    ``gesturecast serve``'s shared denoiser runs it) in the stage the calling thread is timing."""
    _charged.seconds = getattr(_charged, "seconds", 0.0) + seconds


def thread_cpu() -> float:
    """The calling thread's CPU seconds so far, with what was charged to it (:func:`charge_cpu`)."""
    return time.thread_time() + getattr(_charged, "seconds", 0.0)


@dataclass(frozen=True)
class LatencyBudget:
    """Latency budget of the live engine.

    latent_frames: d, motion frames per latent frame (one generator step).
    lookahead_frames: δa, audio feature frames of look-ahead past the latent frame.
    compute_margin_ms: headroom for compute, audio blocks and sending.
    fps: motion (and audio feature) frame rate.
    smoothing_frames: k, motion frames a pose waits for its centred smoothing window.
    """

    latent_frames: int = 4
    lookahead_frames: int = 8
    compute_margin_ms: float = 100.0
    fps: float = MOTION_FPS
    smoothing_frames: int = 0

    def __post_init__(self) -> None:
        if self.latent_frames < 1:
            raise UserError(f"latent frame length must be at least 1 motion frame, got {self.latent_frames}")
        if self.lookahead_frames < 0:
            raise UserError(f"look-ahead must be 0 or more frames, got {self.lookahead_frames}")
        if self.compute_margin_ms < 0:
            raise UserError(f"compute margin must be 0 ms or more, got {self.compute_margin_ms}")
        if self.fps <= 0:
            raise UserError(f"frame rate must be positive, got {self.fps}")
        if self.smoothing_frames < 0:
            raise UserError(f"smoothing must be 0 or more frames, got {self.smoothing_frames}")

    @property
    def algorithmic_ms(self) -> float:
        """Wait for audio and the smoothing window: (d + δa + k) frames."""
        return (self.latent_frames + self.lookahead_frames + self.smoothing_frames) * MS_PER_S / self.fps

    @property
    def total_ms(self) -> float:
        """L in milliseconds."""
        return self.algorithmic_ms + self.compute_margin_ms

    @property
    def total_s(self) -> float:
        """L in seconds (clock units): presentation_time = capture_time + total_s."""
        return self.total_ms / MS_PER_S

    def describe(self) -> str:
        """The start-up line the CLI prints."""
        return (
            f"latency L = {self.total_ms:.0f} ms (latent frame {self.latent_frames} + look-ahead "
            f"{self.lookahead_frames} + smoothing {self.smoothing_frames} frames at {self.fps:g} fps = "
            f"{self.algorithmic_ms:.0f} ms, "
            f"compute margin {self.compute_margin_ms:.0f} ms): delay your audio by {self.total_ms:.0f} ms "
            "to stay in sync"
        )

    def to_dict(self) -> dict[str, float]:
        return {
            "latent_frames": self.latent_frames,
            "lookahead_frames": self.lookahead_frames,
            "smoothing_frames": self.smoothing_frames,
            "compute_margin_ms": self.compute_margin_ms,
            "fps": self.fps,
            "algorithmic_ms": self.algorithmic_ms,
            "latency_budget_ms": self.total_ms,
        }


class _Ring:
    """Ring of float samples, at most ``capacity``, plus exact all-time count, sum and max.

    The storage starts at :data:`INITIAL_RING_SAMPLES` and doubles as samples arrive, so a short
    stream holds kilobytes, not ``capacity`` x 8 bytes per stage (``gesturecast serve`` starts and
    closes many streams; a full-size ring per stage per stream made the process grow by megabytes
    per stream, the freed blocks stranded in the allocator's per-thread arenas).
    """

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self.samples = np.zeros(min(capacity, INITIAL_RING_SAMPLES))  # (size,), size <= capacity
        self.count = 0
        self.total = 0.0
        self.maximum = -np.inf

    def add(self, value: float) -> None:
        if self.count == self.samples.size < self.capacity:  # full before wrapping: grow (samples in order)
            grown = np.zeros(min(2 * self.samples.size, self.capacity))  # (size',)
            grown[: self.count] = self.samples
            self.samples = grown
        self.samples[self.count % self.samples.size] = value
        self.count += 1
        self.total += value
        self.maximum = max(self.maximum, value)

    def recent(self, last: int | None = None) -> np.ndarray:
        """The newest ``last`` samples still held (all held samples when ``last`` is None)."""
        held = min(self.count, self.samples.size)
        n = held if last is None else min(last, held)
        end = self.count % self.samples.size
        return np.take(self.samples, np.arange(end - n, end), mode="wrap")  # (n,)


class LatencyStats:
    """Per-stage timing samples with bounded memory (thread-safe).

    Each stage keeps its newest ``window`` samples in a fixed ring; percentiles are over that window,
    count / mean / max over the whole run. Samples are recorded in seconds, summaries are in ms. Stages timed
    with :meth:`time` also add up the CPU time of the thread that ran them (:meth:`cpu_seconds`): what the work
    cost, where the durations on the clock include waiting and other threads' turns on a busy machine.
    """

    def __init__(self, clock: Clock, window: int = DEFAULT_WINDOW) -> None:
        if window < 1:
            raise ValueError(f"window must be at least 1 sample, got {window}")
        self.clock = clock
        self.window = window
        self._rings: dict[str, _Ring] = {}
        self._cpu: dict[str, float] = {}  # stage -> thread CPU seconds of its timed blocks
        self._lock = threading.Lock()

    def record(self, stage: str, seconds: float, cpu_seconds: float = 0.0) -> None:
        with self._lock:
            ring = self._rings.get(stage)
            if ring is None:
                ring = self._rings[stage] = _Ring(self.window)
            ring.add(float(seconds))
            self._cpu[stage] = self._cpu.get(stage, 0.0) + cpu_seconds

    @contextmanager
    def time(self, stage: str) -> Iterator[None]:
        """``with stats.time("denoiser"): ...`` records the block's duration on the injected clock and the CPU time
        its thread spent in it."""
        start, cpu_start = self.clock.now(), thread_cpu()
        try:
            yield
        finally:
            self.record(stage, self.clock.now() - start, thread_cpu() - cpu_start)

    def cpu_seconds(self, stages: Iterable[str]) -> float:
        """Thread CPU seconds spent in the timed blocks of ``stages``, summed."""
        with self._lock:
            return sum(self._cpu.get(stage, 0.0) for stage in stages)

    def stages(self) -> list[str]:
        with self._lock:
            return list(self._rings)

    def count(self, stage: str) -> int:
        with self._lock:
            ring = self._rings.get(stage)
            return 0 if ring is None else ring.count

    def percentiles_ms(
        self, stage: str, percentiles: tuple[float, ...] = SUMMARY_PERCENTILES, last: int | None = None
    ) -> tuple[float, ...]:
        """Percentiles in ms over the newest ``last`` samples (whole window if None); NaN if none."""
        with self._lock:
            ring = self._rings.get(stage)
            samples = np.empty(0) if ring is None else ring.recent(last)
        if samples.size == 0:
            return tuple(float("nan") for _ in percentiles)
        return tuple(float(v) * MS_PER_S for v in np.percentile(samples, percentiles))

    def stage_summary(self, stage: str) -> dict[str, float | int]:
        """{count, mean, p50, p95, p99, max} in ms for one stage (JSON-able)."""
        p50, p95, p99 = self.percentiles_ms(stage)
        with self._lock:
            ring = self._rings[stage]
            count, total, maximum = ring.count, ring.total, ring.maximum
        return {
            "count": count,
            "mean": total / count * MS_PER_S,
            "p50": p50,
            "p95": p95,
            "p99": p99,
            "max": maximum * MS_PER_S,
        }

    def summary(self) -> dict[str, dict[str, float | int]]:
        """All stages: {stage: stage_summary} (JSON-able)."""
        return {stage: self.stage_summary(stage) for stage in self.stages()}
