"""The one injected monotonic clock (pipecat style): every realtime module reads time through a ``Clock``.

Only :class:`MonotonicClock` touches ``time.*``; tests inject :class:`FakeClock`, which never sleeps.
Times are float seconds on an arbitrary monotonic origin.
"""

from __future__ import annotations

import threading
import time
from typing import Protocol, runtime_checkable


@runtime_checkable
class Clock(Protocol):
    """A monotonic time source that can also wait."""

    def now(self) -> float:
        """Current time in seconds (monotonic, arbitrary origin)."""
        ...

    def sleep_until(self, t: float) -> None:
        """Return once ``now() >= t`` (immediately if ``t`` is already past)."""
        ...

    def wait_until(self, t: float, event: threading.Event) -> bool:
        """Return once ``now() >= t`` or ``event`` is set; True if it is set."""
        ...


class MonotonicClock:
    """The real clock: ``time.monotonic`` and real sleeping."""

    def now(self) -> float:
        return time.monotonic()

    def sleep_until(self, t: float) -> None:
        remaining = t - time.monotonic()
        if remaining > 0.0:
            time.sleep(remaining)

    def wait_until(self, t: float, event: threading.Event) -> bool:
        remaining = t - time.monotonic()
        return event.wait(remaining) if remaining > 0.0 else event.is_set()


class FakeClock:
    """A manually advanced clock for tests: ``sleep_until`` jumps time forward instead of waiting.

    Thread-safe, so a worker thread sleeping on it and a test advancing it do not race.
    """

    def __init__(self, start: float = 0.0) -> None:
        self._now = float(start)
        self._lock = threading.Lock()

    def now(self) -> float:
        with self._lock:
            return self._now

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` (must be >= 0: the clock is monotonic)."""
        if seconds < 0.0:
            raise ValueError(f"a monotonic clock cannot go back ({seconds} s)")
        with self._lock:
            self._now += seconds

    def sleep_until(self, t: float) -> None:
        with self._lock:
            self._now = max(self._now, float(t))

    def wait_until(self, t: float, event: threading.Event) -> bool:
        if event.is_set():
            return True
        self.sleep_until(t)
        return event.is_set()
