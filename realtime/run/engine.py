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

from gesturecast.frames import PoseFrame
from gesturecast.realtime.audio.sources import DEFAULT_CHUNK, AudioChunk, AudioSource, SourceStats
from gesturecast.realtime.generation.degradation import RUNGS
from gesturecast.realtime.pose.session import (
    STAGE_DECODER,
    STAGE_DENOISER,
    STAGE_FEATURES,
    STAGE_POSES,
    GestureSession,
)
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.ladder import DegradationLadder
from gesturecast.realtime.timing.late_warning import LateWarning
from gesturecast.realtime.timing.latency import MS_PER_S, LatencyStats
from gesturecast.realtime.timing.priority import live_switch_interval, raise_thread_priority
from gesturecast.realtime.timing.scheduler import STAGE_SINK, FrameScheduler, SchedulerConfig, SchedulerWorker
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
    gesture_cues: dict = field(default_factory=dict)  # cues by outcome (on time, late, blended, merged, dropped)
    degradation: dict = field(default_factory=dict)  # the ladder's rung and bursts per rung (paced runs only)
    deferred_word_steps: int = 0  # words left queued by a latent step's speech-act budget, summed over the steps

    @property
    def rtf(self) -> float:
        """CPU seconds per second of audio of every stage a frame passes through (:data:`COMPUTE_STAGES`)."""
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
            "gesture_cues": self.gesture_cues,
            "degradation": self.degradation,
            "deferred_word_steps": self.deferred_word_steps,
        }


COMPUTE_STAGES = (STAGE_FEATURES, STAGE_DENOISER, STAGE_DECODER, STAGE_POSES, STAGE_SINK)  # what rtf counts
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
        session.gestures.warm()
        for chunk in warm_up_chunks(session.sample_rate):
            session.push(chunk)
    finally:
        session.stats = kept
        session.reset()
    return clock.now() - start


def compute_seconds(session: GestureSession) -> float:
    """CPU seconds a session's frames cost in every stage: speech features (lip sync included), denoiser, decoder,
    pose building and the outputs."""
    return session.stats.cpu_seconds(COMPUTE_STAGES)


def make_report(session: GestureSession, audio: SourceStats, scheduler_stats: dict,
                interrupted: bool = False, warm_up_s: float = 0.0, degradation: dict | None = None) -> EngineReport:
    """The report of a run whose audio came in as ``audio`` (an :class:`AudioSource`'s stats).

    ``frames`` counts what reached the outputs: with a scheduler, the frames it released (after Ctrl-C the
    frames not yet due were dropped, and are not output); without one (offline), every frame generated.
    """
    return EngineReport(
        audio_seconds=audio.samples / session.sample_rate,
        frames=scheduler_stats.get("released", session.frames_out),
        compute_seconds=compute_seconds(session),
        latency=session.stats.summary(),
        scheduler=scheduler_stats,
        audio={"skipped_samples": audio.skipped_samples, "skip_aheads": audio.skip_aheads,
               "device_overflows": audio.device_overflows, "untimed_blocks": audio.untimed_blocks},
        budget=session.budget.to_dict(),
        nonfinite_poses=session.nonfinite_poses,
        interrupted=interrupted,
        warm_up_s=warm_up_s,
        root=session.travel.to_dict(),
        gesture_cues=session.gestures.cues.summary(),
        degradation=degradation or {},
        deferred_word_steps=session.controls.deferred_word_steps,
    )


class FrameRelease:
    """A session's frames released to ``sink`` at their presentation times by one scheduler worker thread
    (the live engine's, and a pushed :class:`~gesturecast.realtime.run.stream.Stream`'s).

    Paced with a compute margin (and ``adapt``, the default), each burst's share of the margin used moves the
    degradation ladder (:mod:`gesturecast.realtime.timing.ladder`), which sets the rung of the next latent."""

    def __init__(self, session: GestureSession, sink: Sink, clock: Clock,
                 config: SchedulerConfig | None = None, adapt: bool = True) -> None:
        self.session = session
        self.clock = clock
        self.scheduler = FrameScheduler(clock, sink, config, stats=session.stats)
        self.worker = SchedulerWorker(self.scheduler)
        adapts = adapt and self.scheduler.config.paced and session.budget.compute_margin_ms > 0
        self.ladder = DegradationLadder(len(RUNGS)) if adapts else None
        self.late_warning = LateWarning(clock)

    def start(self) -> None:
        self.worker.start()

    def submit(self, frames: list[PoseFrame]) -> None:
        """Queue a burst; paced, record how much of the compute margin its first frame used (audio block wait +
        compute + wake-up: docs/latency.md "Latency settings"), warn when frames stay late, and let the ladder set
        the next latent's rung."""
        if frames and self.scheduler.config.paced:
            margin_s = self.session.budget.compute_margin_ms / MS_PER_S
            used = self.clock.now() - (frames[0].presentation_time - margin_s)
            self.session.stats.record(STAGE_MARGIN_USED, used)
            self.late_warning.observe(used - margin_s)
            if self.ladder is not None:
                self._step_ladder(used / margin_s)
        self.worker.submit(frames)

    def _step_ladder(self, margin_share: float) -> None:
        rung = self.ladder.rung
        if self.ladder.observe(margin_share) != rung:
            self.session.generator.degrade(RUNGS[self.ladder.rung])

    def ladder_report(self) -> dict:
        """The ladder's rung and bursts per rung ({} when the run does not adapt)."""
        return {} if self.ladder is None else self.ladder.to_dict()

    def drain(self, on_wait: Callable[[], None] | None = None) -> None:
        """Wait until every queued frame is released; re-raises the error that stopped the worker."""
        drain(self.worker, on_wait)

    def stop(self) -> None:
        """Stop releasing (frames not yet due are dropped)."""
        self.worker.stop()


class LiveEngine:
    """Runs one stream in real time until the source ends, :meth:`stop` is called, or Ctrl-C.

    Before the source opens, :func:`warm_up` runs every stage once on throwaway audio (``warm=False``
    skips it, for measuring what it saves). Ctrl-C (KeyboardInterrupt on the caller's thread) ends the
    run at once: the source is closed (a microphone within a bounded time), frames not yet due are
    dropped, and :meth:`run` returns the report of what was sent, with ``interrupted`` set; the caller
    decides the exit status. ``adapt=False`` keeps the degradation ladder off (to measure what it does).
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
        on_warm: Callable[[], object] | None = None,
        adapt: bool = True,
    ) -> None:
        self.session = session
        self.warm = warm
        self.on_warm = on_warm  # runs once the stages are warm and the stream is reset, before the source opens
        self.source = source
        self.clock = clock
        self.release = FrameRelease(session, sink, clock, scheduler_config, adapt)
        self.scheduler = self.release.scheduler
        self.status = status
        self._last_frame: PoseFrame | None = None

    def stop(self) -> None:
        """Ask the run to end after the current chunk (thread-safe)."""
        self.source.close()

    def run(self) -> EngineReport:
        """The whole run; paced, with the stream thread's priority raised where allowed and the interpreter's switch
        interval shortened, so the release thread and an audio callback get the GIL within about 1 ms
        (docs/latency.md "On a busy machine")."""
        if not self.scheduler.config.paced:
            return self._run()
        raise_thread_priority()
        with live_switch_interval():
            return self._run()

    def _run(self) -> EngineReport:
        self.release.start()
        chunks = iter(self.source)
        interrupted, warm_up_s = False, 0.0
        try:
            if self.warm:
                warm_up_s = warm_up(self.session, self.clock)
            if self.on_warm is not None:
                self.on_warm()  # e.g. a transcript's cues, in the stream that starts now
            for chunk in chunks:
                self._submit(self.session.push(chunk))
                self._show_status()
            self._submit(self.session.finish())
            self.release.drain(self._show_status)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            chunks.close()  # a microphone stream is closed here, also when the loop body raised
            self.release.stop()
            if self.status is not None:
                self.status.close()
        return make_report(self.session, self.source.stats(), self.scheduler.stats.to_dict(), interrupted,
                           warm_up_s, self.release.ladder_report())

    def _submit(self, frames: list[PoseFrame]) -> None:
        self.release.submit(frames)
        if frames:
            self._last_frame = frames[-1]

    def _show_status(self) -> None:
        if self.status is None:
            return
        last = self._last_frame
        snapshot = build_snapshot(
            self.session.budget,
            self.session.stats,
            self.scheduler.stats,
            self.scheduler.config.output_fps,
            self.source.stats().skipped_samples,
            last.style if last else "",
            bool(last and last.speaking),
            self.release.ladder,
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
    return frames, make_report(session, source.stats(), {})
