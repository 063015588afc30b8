"""One served stream: a bounded audio inbox, a session worker thread and a frame scheduler.

The WebSocket handler only :meth:`ServeStream.feed` s decoded audio (never blocks: a full inbox drops
the message and counts it). The worker turns each message into an :class:`AudioChunk` whose capture
time is its arrival time minus its duration (the client sends a chunk as soon as it is recorded), kept
monotonic so presentation times never go back, and pushes it through the :class:`GestureSession`. Its
denoiser calls go to the server's shared batcher. Frames are released at capture time + L by a
:class:`FrameScheduler` and handed to ``send`` (thread-safe, bounded) as binary frames.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gesturecast.bridges import ws_protocol
from gesturecast.bridges.coords import CoordinateFrame
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.run.engine import compute_seconds
from gesturecast.realtime.serve.protocol import stats_message
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.scheduler import STAGE_END_TO_END, FrameScheduler, SchedulerConfig, SchedulerWorker

logger = logging.getLogger(__name__)

Send = Callable[[bytes | str], None]
LATENCY_KEYS = ("p50", "p95", "p99", "max")
STOP_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class StreamConfig:
    """max_queued_messages: audio messages waiting for the session (beyond: dropped, counted).
    poll_interval_s: how often the worker, after the end of the stream, looks whether its last frames are out
    (while streaming it and the frame releaser sleep until there is work: twenty streams polling burned CPU)."""

    max_queued_messages: int = 64
    poll_interval_s: float = 0.02
    output_fps: float = 30.0


@dataclass(frozen=True)
class FrameSender:
    """The scheduler's sink (scheduler thread): a released pose frame → one binary message through ``send``.

    It holds no reference back to its :class:`ServeStream`, so a closed stream (its session, KV caches, decoder
    session, statistics rings) is freed by reference counting the moment its connection lets go of it, not later,
    whenever the garbage collector would have found a stream ↔ scheduler cycle."""

    clock: Clock
    coords: CoordinateFrame
    send: Send

    def __call__(self, frame: PoseFrame) -> None:
        send_unix = time.time()  # wire timestamps are Unix time; the latency arithmetic stays on the clock
        capture_unix = send_unix - (self.clock.now() - frame.capture_time)
        self.send(ws_protocol.binary_frame(frame, self.coords, capture_unix, send_unix))


class ServeStream:
    """Audio messages in (any thread), binary pose frames out through ``send``; :meth:`stop` frees it."""

    def __init__(
        self,
        stream_id: str,
        session: GestureSession,
        clock: Clock,
        send: Send,
        coords: CoordinateFrame,
        config: StreamConfig | None = None,
        on_finished: Callable[[], None] | None = None,
        delivery_counters: Callable[[], dict[str, int]] | None = None,
    ) -> None:
        self.stream_id = stream_id
        self.session = session
        self.clock = clock
        self.send = send
        self.coords = coords
        self.config = config or StreamConfig()
        self.on_finished = on_finished
        self.delivery_counters = delivery_counters  # the connection's outbox drops and slow-client skips
        self.dropped_samples = 0
        self.error: str | None = None
        # audio messages in arrival order, then None once the stream ends or stops (bounded by feed)
        self._inbox: queue.SimpleQueue[tuple[np.ndarray, float] | None] = queue.SimpleQueue()
        self._samples = 0
        self._next_capture = -np.inf
        self._stopped = threading.Event()
        release = SchedulerConfig(self.config.output_fps)
        self.scheduler = FrameScheduler(clock, FrameSender(clock, coords, send), release, stats=session.stats)
        self._releaser = SchedulerWorker(self.scheduler)
        self._worker = threading.Thread(target=self._run, name=f"stream-{stream_id}", daemon=True)

    def start(self) -> ServeStream:
        self._releaser.start()
        self._worker.start()
        return self

    # ---- handler side (event-loop thread) ----
    def feed(self, samples: np.ndarray, arrival: float) -> bool:
        """Queue one decoded audio message; False (and counted) if the inbox is full (only this thread puts
        audio, so the size it sees cannot grow behind its back)."""
        if self._inbox.qsize() >= self.config.max_queued_messages:
            self.dropped_samples += len(samples)
            return False
        self._inbox.put((samples, arrival))
        return True

    def end(self) -> None:
        """No more audio: finish the look-ahead, release the last frames, send stats, then ``on_finished``."""
        self._inbox.put(None)  # after the audio already queued

    def stop(self) -> None:
        """Stop now (client gone): threads end, queued audio and frames are discarded."""
        self._stopped.set()
        self._inbox.put(None)  # wakes the worker
        self._worker.join(STOP_TIMEOUT_S)
        self._releaser.stop()

    # ---- worker thread ----
    def _run(self) -> None:
        try:
            self._consume()
        except Exception as error:  # one broken stream must not take the server down: report and end it
            logger.exception("stream %s failed", self.stream_id)
            self.error = f"{type(error).__name__}: {error}"
            self.send(ws_protocol.error_message(f"stream {self.stream_id} failed: {self.error}"))
            self._finished()

    def _consume(self) -> None:
        while (message := self._inbox.get()) is not None and not self._stopped.is_set():
            self._releaser.submit(self.session.push(self._chunk(*message)))
        if not self._stopped.is_set():
            self._finish()

    def _chunk(self, samples: np.ndarray, arrival: float) -> AudioChunk:
        duration = len(samples) / SAMPLE_RATE
        capture = max(arrival - duration, self._next_capture)  # never earlier than the previous chunk's end
        chunk = AudioChunk(samples, self._samples, capture)
        self._samples += len(samples)
        self._next_capture = capture + duration
        return chunk

    def _finish(self) -> None:
        self._releaser.submit(self.session.finish())
        while (due := self.scheduler.next_due()) is not None and self._releaser.running:
            if self._stopped.is_set():
                return
            self.clock.sleep_until(min(due, self.clock.now() + self.config.poll_interval_s))
        self.send(stats_message(self.stats()))
        self._finished()

    def _finished(self) -> None:
        if self.on_finished is not None:
            self.on_finished()

    def stats(self) -> dict:
        """Per-stream numbers (JSON-able; ms)."""
        summary = self.session.stats.summary()
        end_to_end = summary.get(STAGE_END_TO_END, {})
        audio_seconds = self._samples / SAMPLE_RATE
        return {
            "stream": self.stream_id,
            "audio_seconds": audio_seconds,
            "frames": self.scheduler.stats.released,  # sent: frames not yet due when a stream stops are not
            "latency_budget_ms": self.session.budget.total_ms,
            "end_to_end_ms": {key: end_to_end.get(key) for key in LATENCY_KEYS},
            "stages_ms": {name: {"p50": s["p50"], "p95": s["p95"]} for name, s in summary.items()},
            "stream_rtf": compute_seconds(self.session) / audio_seconds if audio_seconds else None,
            "deadline_misses": self.scheduler.stats.deadline_misses,
            "late_releases": self.scheduler.stats.late_releases,
            "scheduler_overflow_drops": self.scheduler.stats.overflow_drops,
            "audio_dropped_samples": self.dropped_samples,
            "nonfinite_poses": self.session.nonfinite_poses,
            "deferred_word_steps": self.session.controls.deferred_word_steps,
            **(self.delivery_counters() if self.delivery_counters is not None else {}),
            "error": self.error,
        }
