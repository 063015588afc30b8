"""The words' work off a live stream's thread: speech-act decisions (about a millisecond a word) and sentence
alignment run on one worker thread, in the order they were handed over, so generating a frame never waits for them.

A caller that wants the result (a library call answering how many cues play) waits on the job's future; the stream's
own thread never does: it hands the job over and places what has been decided at its next latent
(:meth:`GestureDirector.play`), so a decision that comes after its words' window was generated plays late, or is
dropped with a log line, as any late cue is (:class:`~gesturecast.realtime.gestures.cues.CuePlan`). A full queue
refuses a job with a log line instead of waiting. Offline runs have no worker: everything is decided at once, in
order, and the output stays bit-identical.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future

from gesturecast.log_throttle import ThrottledLog

logger = logging.getLogger(__name__)
MAX_JOBS = 256  # jobs waiting for the worker: far more than a stream hands over between two latents


class WordsWorker:
    """One daemon thread running handed-over jobs in order (module docstring)."""

    def __init__(self, max_jobs: int = MAX_JOBS) -> None:
        self._jobs: queue.Queue[tuple[Callable[[], object], Future] | None] = queue.Queue(max_jobs)
        self._full_log = ThrottledLog(logger)
        self.refused = 0  # jobs refused by a full queue
        self._thread = threading.Thread(target=self._run, name="gesturecast-words", daemon=True)
        self._thread.start()

    def submit(self, job: Callable[[], object]) -> Future:
        """Queue ``job``; its future holds the result (or the exception). A full queue refuses it at once: the
        future then holds a RuntimeError, and a line is logged."""
        future: Future = Future()
        try:
            self._jobs.put_nowait((job, future))
        except queue.Full:
            self.refused += 1
            self._full_log.log(logging.WARNING, "words work refused: the words worker is behind (queue full)")
            future.set_exception(RuntimeError("the words worker is behind"))
        return future

    def close(self) -> None:
        """Finish the queued jobs and stop the thread."""
        self._jobs.put(None)
        self._thread.join()

    def _run(self) -> None:
        while (item := self._jobs.get()) is not None:
            job, future = item
            try:
                future.set_result(job())
            except Exception as error:  # the job's failure is its caller's, never the worker's end
                future.set_exception(error)
