"""The live engine: an audio source drives a session; a scheduler releases its frames to the bridges on time.

Threads: the source (for a microphone, PortAudio's callback only copies into a ring buffer) and
the session run on the caller's thread; the :class:`SchedulerWorker` releases frames at their
presentation times on the one injected clock. ``generate`` uses the same session with a fast
file source and streams the frames to files instead (see :func:`offline_batches`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from gesturecast.realtime.audio.sources import DEFAULT_CHUNK, AudioChunk, AudioSource
from gesturecast.realtime.session import GestureSession
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.frames import PoseFrame
from gesturecast.realtime.timing.latency import MS_PER_S, LatencyStats
from gesturecast.realtime.timing.scheduler import FrameScheduler, SchedulerConfig, SchedulerWorker
from gesturecast.realtime.timing.status import StatusLine, build_snapshot

logger = logging.getLogger(__name__)

Sink = Callable[[PoseFrame], None]
STAGE_MARGIN_USED = "margin_used"  # of each burst's earliest-due frame: ready time − (due time − compute margin)


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
    nonfinite_poses: int = 0  # generated poses with NaN/inf, replaced by the last good pose
    outputs: dict = field(default_factory=dict)  # per bridge counters (e.g. WebSocket drops and skips)
    interrupted: bool = False  # ended by Ctrl-C (KeyboardInterrupt) before the source ran out
    warm_up_s: float = 0.0  # spent warming the stages up before the source opened
    root: dict = field(default_factory=dict)  # RootTravel: max distance and net travel (m), max facing (°)

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
            "nonfinite_poses": self.nonfinite_poses,
            "outputs": self.outputs,
            "interrupted": self.interrupted,
            "warm_up_ms": self.warm_up_s * MS_PER_S,
            "root": self.root,
        }


COMPUTE_STAGES = ("features", "denoiser", "decoder")
WARM_UP_S = 1.5  # throwaway audio run through every stage before a live source opens (half silence, half noise)
WARM_UP_NOISE_RMS = 0.1  # -20 dBFS white noise: the VAD calls it speech, so the speaking path runs too
WARM_UP_SEED = 0


def warm_up_chunks(sample_rate: int, seconds: float = WARM_UP_S) -> list[AudioChunk]:
    """Silence then white noise, in the live chunk size, with capture times from 0."""
    half = int(seconds * sample_rate / 2)
    noise = np.random.default_rng(WARM_UP_SEED).normal(0.0, WARM_UP_NOISE_RMS, half).astype(np.float32)  # (n,)
    audio = np.concatenate([np.zeros(half, np.float32), noise])  # (2n,)
    return [AudioChunk(audio[start : start + DEFAULT_CHUNK], start, start / sample_rate)
            for start in range(0, audio.shape[0], DEFAULT_CHUNK)]


def warm_up(session: GestureSession, clock: Clock) -> float:
    """Run features, denoiser and decoder on throwaway audio, then reset the stream; returns the seconds spent.

    The first calls of an ONNX session and of the feature code allocate and pick kernels; done while a
    microphone is already open, they delay the first frames past their deadlines. The session's
    statistics do not see the warm-up, and after it the session starts from sample 0 with its seed.
    """
    kept, session.stats = session.stats, LatencyStats(clock)
    start = clock.now()
    try:
        for chunk in warm_up_chunks(session.sample_rate):
            session.push(chunk)
    finally:
        session.stats = kept
        session.reset()
    return clock.now() - start


def compute_seconds(session: GestureSession) -> float:
    """Total time spent in the compute stages of a session (mean ms x count, summed)."""
    summary = session.stats.summary()
    return sum(s["mean"] * s["count"] for name, s in summary.items() if name in COMPUTE_STAGES) / 1000.0


def make_report(session: GestureSession, source: AudioSource, scheduler_stats: dict,
                interrupted: bool = False, warm_up_s: float = 0.0) -> EngineReport:
    audio = source.stats()
    return EngineReport(
        audio_seconds=audio.samples / session.sample_rate,
        frames=session.frames_out,
        compute_seconds=compute_seconds(session),
        latency=session.stats.summary(),
        scheduler=scheduler_stats,
        audio={"dropped_samples": audio.dropped_samples, "overruns": audio.overruns,
               "device_overflows": audio.device_overflows, "untimed_blocks": audio.untimed_blocks},
        budget=session.budget.to_dict(),
        nonfinite_poses=session.nonfinite_poses,
        interrupted=interrupted,
        warm_up_s=warm_up_s,
        root=session.travel.to_dict(),
    )


class LiveEngine:
    """Runs one stream in real time until the source ends, :meth:`stop` is called, or Ctrl-C.

    Before the source opens, :func:`warm_up` runs every stage once on throwaway audio (``warm=False``
    skips it, for measuring what it saves). Ctrl-C (KeyboardInterrupt on the caller's thread) ends the
    run at once: the source is closed (a microphone within a bounded time), frames not yet due are
    dropped, and :meth:`run` returns the report of what was sent, with ``interrupted`` set; the caller
    decides the exit status.
    """

    def __init__(
        self,
        session: GestureSession,
        source: AudioSource,
        sink: Sink,
        clock: Clock,
        scheduler_config: SchedulerConfig | None = None,
        status: StatusLine | None = None,
        warm: bool = True,
    ) -> None:
        self.session = session
        self.warm = warm
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
        chunks = iter(self.source)
        interrupted, warm_up_s = False, 0.0
        try:
            if self.warm:
                warm_up_s = warm_up(self.session, self.clock)
            for chunk in chunks:
                self._submit(self.session.push(chunk), worker)
                self._show_status()
            self._submit(self.session.finish(), worker)
            self._drain(worker)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            chunks.close()  # a microphone stream is closed here, also when the loop body raised
            worker.stop()
            if self.status is not None:
                self.status.close()
        return make_report(self.session, self.source, self.scheduler.stats.to_dict(), interrupted, warm_up_s)

    def _submit(self, frames: list[PoseFrame], worker: SchedulerWorker) -> None:
        """Hand a burst to the scheduler; paced, record how much of the compute margin its first frame used
        (audio block wait + compute + wake-up: docs/latency.md "Latency settings")."""
        if frames and self.scheduler.config.paced:
            budget = self.session.budget
            used = self.clock.now() - (frames[0].presentation_time - budget.compute_margin_ms / MS_PER_S)
            self.session.stats.record(STAGE_MARGIN_USED, used)
        worker.submit(frames)
        if frames:
            self._last_frame = frames[-1]

    def _drain(self, worker: SchedulerWorker) -> None:
        drain(worker, self._show_status)

    def _show_status(self) -> None:
        if self.status is None:
            return
        last = self._last_frame
        snapshot = build_snapshot(
            self.session.budget,
            self.session.stats,
            self.scheduler.stats,
            self.scheduler.config.output_fps,
            self.source.stats().dropped_samples,
            last.style if last else "",
            bool(last and last.speaking),
        )
        self.status.update(snapshot)


def drain(worker: SchedulerWorker, on_wait: Callable[[], None] | None = None) -> None:
    """Wait until ``worker`` has released every queued frame at its time; re-raises the error that stopped it.

    ``on_wait`` runs after each wait (the live status line)."""
    scheduler = worker.scheduler
    poll = scheduler.config.poll_interval_s
    while (due := scheduler.next_due()) is not None and worker.running:
        scheduler.clock.sleep_until(max(due, scheduler.clock.now() + poll))  # unpaced frames are due at once: no spin
        if on_wait is not None:
            on_wait()
    if worker.error is not None:
        raise worker.error


def offline_batches(session: GestureSession, source: AudioSource) -> Iterator[list[PoseFrame]]:
    """The session fed as fast as possible (the `generate` path): each chunk's frames, in order, then the last."""
    for chunk in source:
        yield session.push(chunk)
    yield session.finish()


def run_offline(session: GestureSession, source: AudioSource) -> tuple[list[PoseFrame], EngineReport]:
    """:func:`offline_batches` collected in one list (for short clips: evaluation, tests)."""
    frames = [frame for batch in offline_batches(session, source) for frame in batch]
    return frames, make_report(session, source, {})
