"""At most one log line per interval for a message that can come in floods (a cue per OSC packet or per word).

:class:`ThrottledLog` logs the first message of an interval and counts the others; the count goes with the next line
that is logged ("… (37 more like it in the last 5 s not logged)"), so a flood of any size writes one line per interval.
Counters elsewhere (a stream's report) still count every event.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

LOG_INTERVAL_S = 5.0


class ThrottledLog:
    """One kind of message to ``logger``, at most one line per ``interval_s`` of ``clock`` (module docstring)."""

    def __init__(self, logger: logging.Logger, interval_s: float = LOG_INTERVAL_S,
                 clock: Callable[[], float] | None = None) -> None:
        self.logger = logger
        self.interval_s = interval_s
        self._clock = clock  # None: time.monotonic
        self._next_line = float("-inf")  # clock time from which the next message is logged
        self._held = 0  # messages not logged since the last line

    def log(self, level: int, message: str) -> None:
        now = (self._clock or time.monotonic)()
        if now < self._next_line:
            self._held += 1
            return
        if self._held:
            message += f" ({self._held} more like it in the last {self.interval_s:g} s not logged)"
        self.logger.log(level, message)
        self._held, self._next_line = 0, now + self.interval_s
