"""The live engine: an audio source drives a session; a scheduler releases its frames to the bridges on time.

Threads: the source (for a microphone, PortAudio's callback only copies into a ring buffer) and
the session run on the caller's thread; the :class:`SchedulerWorker` releases frames at their
presentation times on the one injected clock. ``generate`` uses the same session with a fast
file source and streams the frames to files instead (see :func:`offline_batches`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from gesturecast.realtime.audio.sources import AudioSource
from gesturecast.realtime.session import GestureSession
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.frames import PoseFrame
from gesturecast.realtime.timing.scheduler import FrameScheduler, SchedulerConfig, SchedulerWorker
from gesturecast.realtime.timing.status import StatusLine, build_snapshot

logger = logging.getLogger(__name__)

Sink = Callable[[PoseFrame], None]


@dataclass
class EngineReport:
    """What a run measured: JSON-able via :meth:`to_dict`."""

    audio_seconds: float
    frames: int
    compute_seconds: float
    latency: dict
    scheduler: dict
    audio: dict
    budget: dict

    @property
    def rtf(self) -> float:
        """Compute seconds per second of audio (features + denoiser + decoder)."""
        return self.compute_seconds / self.audio_seconds if self.audio_seconds else float("nan")

    def to_dict(self) -> dict:
        return {
            "audio_seconds": self.audio_seconds,
            "frames": self.frames,
            "rtf": self.rtf,
            "latency_budget": self.budget,
            "stages_ms": self.latency,
            "scheduler": self.scheduler,
            "audio": self.audio,
        }


COMPUTE_STAGES = ("features", "denoiser", "decoder")


def compute_seconds(session: GestureSession) -> float:
    """Total time spent in the compute stages of a session (mean ms x count, summed)."""
    summary = session.stats.summary()
    return sum(s["mean"] * s["count"] for name, s in summary.items() if name in COMPUTE_STAGES) / 1000.0


def make_report(session: GestureSession, source: AudioSource, scheduler_stats: dict) -> EngineReport:
    audio = source.stats()
    return EngineReport(
        audio_seconds=audio.samples / session.sample_rate,
        frames=session.frames_out,
        compute_seconds=compute_seconds(session),
        latency=session.stats.summary(),
        scheduler=scheduler_stats,
        audio={"dropped_samples": audio.dropped_samples, "overruns": audio.overruns,
               "device_overflows": audio.device_overflows},
        budget=session.budget.to_dict(),
    )


class LiveEngine:
    """Runs one stream in real time until the source ends (or :meth:`stop` is called)."""

    def __init__(
        self,
        session: GestureSession,
        source: AudioSource,
        sink: Sink,
        clock: Clock,
        scheduler_config: SchedulerConfig | None = None,
        status: StatusLine | None = None,
    ) -> None:
        self.session = session
        self.source = source
        self.clock = clock
        self.scheduler = FrameScheduler(clock, sink, scheduler_config, stats=session.stats)
        self.status = status
        self._last_frame: PoseFrame | None = None

    def stop(self) -> None:
        """Ask the run to end after the current chunk (thread-safe)."""
        self.source.close()

    def run(self) -> EngineReport:
        worker = SchedulerWorker(self.scheduler)
        worker.start()
        try:
            for chunk in self.source:
                self._submit(self.session.push(chunk), worker)
                self._show_status()
            self._submit(self.session.finish(), worker)
            self._drain(worker)
        finally:
            worker.stop()
            if self.status is not None:
                self.status.close()
        return make_report(self.session, self.source, self.scheduler.stats.to_dict())

    def _submit(self, frames: list[PoseFrame], worker: SchedulerWorker) -> None:
        worker.submit(frames)
        if frames:
            self._last_frame = frames[-1]

    def _drain(self, worker: SchedulerWorker) -> None:
        """Wait until the worker has released every queued frame at its time."""
        while (due := self.scheduler.next_due()) is not None and worker.running:
            self.clock.sleep_until(due)
            self._show_status()
        if worker.error is not None:
            raise worker.error

    def _show_status(self) -> None:
        if self.status is None:
            return
        last = self._last_frame
        snapshot = build_snapshot(
            self.session.budget,
            self.session.stats,
            self.scheduler.stats,
            self.source.stats().dropped_samples,
            last.style if last else "",
            bool(last and last.speaking),
        )
        self.status.update(snapshot)


def offline_batches(session: GestureSession, source: AudioSource) -> Iterator[list[PoseFrame]]:
    """The session fed as fast as possible (the `generate` path): each chunk's frames, in order, then the last."""
    for chunk in source:
        yield session.push(chunk)
    yield session.finish()


def run_offline(session: GestureSession, source: AudioSource) -> tuple[list[PoseFrame], EngineReport]:
    """:func:`offline_batches` collected in one list (for short clips: evaluation, tests)."""
    frames = [frame for batch in offline_batches(session, source) for frame in batch]
    return frames, make_report(session, source, {})
