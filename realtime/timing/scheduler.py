"""Fixed-latency frame release on the injected clock, with optional 60 fps slerp upsampling.

The generator submits each :class:`PoseFrame` as soon as it exists, carrying
presentation_time = capture_time + L. The scheduler hands it to the sink (the bridges) at that
time on the one injected clock. The engine either calls :meth:`FrameScheduler.pump` /
:meth:`FrameScheduler.run_until` itself, or runs a :class:`SchedulerWorker` thread.

Deadline policy: a frame submitted after its presentation time is a *deadline miss* (late computation).
It is counted and still sent at once, never dropped, so recorders receive every frame and the avatar
never holds a stale pose longer than necessary. Release lateness (release time - presentation time) is
tracked for every frame; a frame released more than half an output frame after its presentation time
is a *late release*, counted whatever made it late (late computation, a slow bridge, a starved thread).
Unpaced (``paced=False``, ``live --pace fast``): frames are released as soon as they are queued; their
presentation times are not on the clock, so no deadline, lateness or end-to-end time is recorded.

The pending queue is bounded; on overflow the oldest pending frame is dropped and counted
(in live use at most L * fps frames are ever pending, so this only guards a runaway producer).
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_slerp
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import MS_PER_S, LatencyStats, thread_cpu

logger = logging.getLogger(__name__)

BASE_FPS = 30.0
UPSAMPLED_FPS = 60.0
HALF = 0.5
STAGE_LATENESS = "release_lateness"
STAGE_SINK = "bridge"
STAGE_END_TO_END = "end_to_end"

Sink = Callable[[PoseFrame], None]


@dataclass(frozen=True)
class SchedulerConfig:
    """output_fps: 30 (as generated) or 60 (a slerped midpoint between consecutive frames).
    max_pending: bound on queued frames (drop-oldest with a counter beyond it).
    poll_interval_s: how often :func:`~gesturecast.realtime.run.engine.drain` looks for the end of the queue (the
    :class:`SchedulerWorker` itself sleeps until the next due frame or a new one).
    late_release_frames: release lateness, in output frames, beyond which a release counts as late.
    paced: release at presentation times (True) or as soon as queued (False: a file read as fast as possible).
    """

    output_fps: float = BASE_FPS
    max_pending: int = 512
    poll_interval_s: float = 0.005
    late_release_frames: float = HALF
    paced: bool = True

    @property
    def late_release_s(self) -> float:
        """Release lateness in seconds beyond which a release counts as late."""
        return self.late_release_frames / self.output_fps

    def __post_init__(self) -> None:
        if self.output_fps not in (BASE_FPS, UPSAMPLED_FPS):
            raise ValueError(f"output_fps must be {BASE_FPS:g} or {UPSAMPLED_FPS:g}, got {self.output_fps}")
        if self.max_pending < 1:
            raise ValueError(f"max_pending must be at least 1, got {self.max_pending}")


@dataclass
class SchedulerStats:
    """Counters of one scheduler (output frames: at 60 fps midpoints count too)."""

    submitted: int = 0
    released: int = 0
    deadline_misses: int = 0
    late_releases: int = 0
    overflow_drops: int = 0
    max_lateness_s: float = 0.0

    def to_dict(self) -> dict[str, float | int]:
        return {
            "submitted": self.submitted,
            "released": self.released,
            "deadline_misses": self.deadline_misses,
            "late_releases": self.late_releases,
            "overflow_drops": self.overflow_drops,
            "max_lateness_ms": self.max_lateness_s * MS_PER_S,
        }


def midpoint_frame(a: PoseFrame, b: PoseFrame) -> PoseFrame:
    """The pose halfway between two consecutive frames: slerped rotations, linear root and times.

    Sequence numbers are in output (60 fps) units: the midpoint after input frame k is 2k + 1.
    """
    return PoseFrame(
        seq=2 * a.seq + 1,
        capture_time=HALF * (a.capture_time + b.capture_time),
        presentation_time=HALF * (a.presentation_time + b.presentation_time),
        root_position=HALF * (np.asarray(a.root_position) + np.asarray(b.root_position)),  # (3,)
        rotations=quat_slerp(np.asarray(a.rotations), np.asarray(b.rotations), HALF),  # (J, 4)
        style=a.style,
        speaking=a.speaking,
        visemes=None if a.visemes is None or b.visemes is None else HALF * (a.visemes + b.visemes),  # (5,)
        gesture=a.gesture,
        face=None if a.face is None or b.face is None else HALF * (a.face + b.face),  # (8,)
    )


class FrameScheduler:
    """Releases submitted frames to ``sink`` at their presentation times on ``clock`` (thread-safe).

    Frames must be submitted in non-decreasing presentation time (the generator's order); ValueError otherwise.
    If ``stats`` is given, each release records release lateness, the sink's duration ("bridge") and
    capture-to-sent time ("end_to_end", measured after the sink returns).
    """

    def __init__(
        self, clock: Clock, sink: Sink, config: SchedulerConfig | None = None, stats: LatencyStats | None = None
    ) -> None:
        self.clock = clock
        self.sink = sink
        self.config = config or SchedulerConfig()
        self.latency_stats = stats
        self.stats = SchedulerStats()
        self._pending: deque[PoseFrame] = deque()
        self._previous: PoseFrame | None = None
        self._lock = threading.Lock()
        self.queued = threading.Event()  # set by every submit: an idle releaser wakes on it

    @property
    def upsampling(self) -> bool:
        return self.config.output_fps == UPSAMPLED_FPS

    def submit(self, frame: PoseFrame) -> None:
        """Queue one generated frame (and, at 60 fps, the midpoint before it)."""
        now = self.clock.now()
        with self._lock:
            for out in self._output_frames(frame):
                self._enqueue(out, now)
            self._previous = frame
        self.queued.set()

    def _output_frames(self, frame: PoseFrame) -> list[PoseFrame]:
        if not self.upsampling:
            return [frame]
        renumbered = replace(frame, seq=2 * frame.seq)
        previous = self._previous
        if previous is None or frame.seq != previous.seq + 1:
            return [renumbered]
        return [midpoint_frame(previous, frame), renumbered]

    def _enqueue(self, frame: PoseFrame, now: float) -> None:
        if self._pending and frame.presentation_time < self._pending[-1].presentation_time:
            raise ValueError(
                f"frame {frame.seq} is due at {frame.presentation_time:.4f} s, before the frame queued ahead of it"
            )
        self.stats.submitted += 1
        if self.config.paced and now > frame.presentation_time:
            self.stats.deadline_misses += 1
            late_ms = (now - frame.presentation_time) * MS_PER_S
            logger.debug("frame %d missed its deadline by %.1f ms", frame.seq, late_ms)
        if len(self._pending) >= self.config.max_pending:
            self._pending.popleft()
            self.stats.overflow_drops += 1
        self._pending.append(frame)

    def next_due(self) -> float | None:
        """Presentation time of the next pending frame, or None when nothing is queued."""
        with self._lock:
            return self._pending[0].presentation_time if self._pending else None

    @property
    def pending(self) -> int:
        with self._lock:
            return len(self._pending)

    def pump(self) -> int:
        """Send every frame that is due now; returns how many were sent."""
        sent = 0
        while (frame := self._pop_due()) is not None:
            self._release(frame)
            sent += 1
        return sent

    def _pop_due(self) -> PoseFrame | None:
        now = self.clock.now()
        with self._lock:
            if self._pending and (not self.config.paced or self._pending[0].presentation_time <= now):
                return self._pending.popleft()
        return None

    def _release(self, frame: PoseFrame) -> None:
        start, cpu_start = self.clock.now(), thread_cpu()
        self.sink(frame)
        end = self.clock.now()
        with self._lock:
            self.stats.released += 1
        if self.latency_stats is not None:
            self.latency_stats.record(STAGE_SINK, end - start, thread_cpu() - cpu_start)
        if not self.config.paced:
            return
        lateness = start - frame.presentation_time
        with self._lock:
            self.stats.max_lateness_s = max(self.stats.max_lateness_s, lateness)
            if lateness > self.config.late_release_s:
                self.stats.late_releases += 1
        if self.latency_stats is not None:
            self.latency_stats.record(STAGE_LATENESS, lateness)
            self.latency_stats.record(STAGE_END_TO_END, end - frame.capture_time)

    def run_until(self, t: float) -> int:
        """Sleep on the clock, releasing each frame at its time, until ``t``; returns frames sent."""
        sent = self.pump()
        while (due := self.next_due()) is not None and due <= t:
            self.clock.sleep_until(due)
            sent += self.pump()
        self.clock.sleep_until(t)
        return sent + self.pump()

    def flush(self) -> int:
        """Release everything still queued, each at its time (end of stream); returns frames sent."""
        sent = 0
        while (due := self.next_due()) is not None:
            sent += self.run_until(due)
        return sent


class SchedulerWorker:
    """A daemon thread that keeps a :class:`FrameScheduler` releasing frames on time.

    It sleeps until the next due frame (a frame submitted meanwhile is due no earlier: frames come in presentation
    order) or, with none queued, until one is submitted: about one wake-up per released frame, where polling every
    few milliseconds woke each of twenty served streams' releasers hundreds of times a second.
    If the sink raises, the thread logs it, keeps it in ``error`` for the engine to re-raise, and ends.
    """

    def __init__(self, scheduler: FrameScheduler) -> None:
        self.scheduler = scheduler
        self.error: Exception | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="frame-scheduler", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self, timeout_s: float = 1.0) -> None:
        """Stop the thread (frames still queued stay queued; call ``scheduler.flush()`` to send them)."""
        self._stop.set()
        self.scheduler.queued.set()  # wakes an idle wait
        self._thread.join(timeout_s)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    def submit(self, frames: list[PoseFrame]) -> None:
        """Queue generated frames for release; first re-raises the error that stopped the thread, if any."""
        if self.error is not None:
            raise self.error
        for frame in frames:
            self.scheduler.submit(frame)

    def _loop(self) -> None:
        try:
            self._release_until_stopped()
        except Exception as error:  # a failing sink must surface in the engine, not vanish with the thread
            logger.exception("frame scheduler stopped: the output failed")
            self.error = error

    def _release_until_stopped(self) -> None:
        scheduler = self.scheduler
        while not self._stop.is_set():
            due = scheduler.next_due()
            if due is None:
                scheduler.queued.wait()
                scheduler.queued.clear()  # a frame submitted since is queued already: next_due sees it
            elif not scheduler.clock.wait_until(due, self._stop):
                scheduler.pump()
