"""``bench serve --flood``: one client floods ``words`` messages beside the measured streams; what it costs them.

The flooder streams its own audio at real-time pace like the others and, meanwhile, sends 500-word ``words``
control messages as fast as its socket takes them. The JSON says, per measured stream, the share of late frames
(deadline misses per frame sent) and its p95 against the latency budget L; for the flooder, the messages sent,
refused (each answered with an ``error`` naming the limit) and applied, and whether its own stream went on; and
how many log lines the server wrote (:class:`LogLines`: the most in any one second, and the average).
"""

from __future__ import annotations

import os
import sys
import tempfile
import threading
import time

from gesturecast.tools.bench.serve_client import ClientResult

FLOOD_WORDS_PER_MESSAGE = 500
RATE_LIMIT_MARK = "rate limit"  # how a refusal for the rate names itself (gesturecast/message_rate.py)
LOG_SAMPLE_S = 1.0


def stream_lateness(stats: dict) -> dict:
    """One stream's stats message → its late-frame share (%) and p95 minus L (ms)."""
    frames = stats.get("frames") or 0
    p95 = stats.get("end_to_end_ms", {}).get("p95")
    budget = stats.get("latency_budget_ms")
    return {"frames": frames,
            "late_pct": 100.0 * stats.get("deadline_misses", 0) / frames if frames else None,
            "p95_over_budget_ms": p95 - budget if p95 is not None and budget is not None else None}


def flood_summary(flooder: ClientResult) -> dict:
    """What the flooding client sent, what was refused and applied, and whether its stream went on."""
    refused = sum(1 for message in flooder.errors if RATE_LIMIT_MARK in message)
    applied = sum(1 for message in flooder.messages if message.get("type") == "ack")
    stats = flooder.stats or {}
    others = [message for message in flooder.errors if RATE_LIMIT_MARK not in message]
    return {"messages_sent": flooder.flood_sent, "refused_rate_limited": refused, "applied": applied,
            "other_errors": len(others), "other_error_examples": sorted(set(others))[:3],
            "frames_received": len(flooder.frames),
            "server_rate_limited_messages": stats.get("rate_limited_messages"),
            "own_stream": stream_lateness(stats) if stats else None}


class LogLines:
    """Counts the lines written to this process's standard error (file descriptor 2, which the server and its
    worker processes inherit) while the ``with`` block runs: they go to a file, sampled every second, and are
    written back to the real standard error at the end (nothing is lost, only delayed)."""

    def __init__(self) -> None:
        self.lines = 0
        self.max_per_second = 0
        self.seconds = 0.0
        self._file = tempfile.TemporaryFile()  # noqa: SIM115 (closed in __exit__)
        self._saved_fd = -1
        self._previous = 0  # lines at the last sample
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, name="log-lines", daemon=True)

    def _count(self) -> int:
        return os.pread(self._file.fileno(), os.fstat(self._file.fileno()).st_size, 0).count(b"\n")

    def _sample(self) -> None:
        while not self._done.wait(LOG_SAMPLE_S):
            self._tick()

    def _tick(self) -> None:
        now = self._count()
        self.max_per_second = max(self.max_per_second, now - self._previous)
        self._previous = now

    def __enter__(self) -> LogLines:
        sys.stderr.flush()
        self._saved_fd = os.dup(2)
        os.dup2(self._file.fileno(), 2)
        self._start = time.monotonic()
        self._thread.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        sys.stderr.flush()
        self._done.set()
        self._thread.join()
        self._tick()  # the last (partial) second
        os.dup2(self._saved_fd, 2)
        os.close(self._saved_fd)
        self.seconds = time.monotonic() - self._start
        self.lines = self._count()
        self._file.seek(0)
        sys.stderr.buffer.write(self._file.read())
        sys.stderr.flush()
        self._file.close()

    def to_dict(self) -> dict:
        return {"lines": self.lines, "max_per_second": self.max_per_second,
                "per_second": self.lines / self.seconds if self.seconds else None}
