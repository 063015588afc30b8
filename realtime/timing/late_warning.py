"""Say it while it happens: one warning line when the frames stay late for more than a moment.

Each paced burst reports how late its first frame was ready (ready time − presentation time; ≤ 0 is on time).
Once bursts have been late for :data:`SUSTAINED_S` in a row, one line says by how much and what to do; then at
most one line per :data:`WARNING_INTERVAL_S` while it lasts. A burst on time ends the episode.
"""

from __future__ import annotations

import logging
import math

from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import MS_PER_S

logger = logging.getLogger(__name__)

SUSTAINED_S = 1.0  # late this long in a row before a warning: one slow burst is not worth a line
WARNING_INTERVAL_S = 10.0  # at most one line this often


class LateWarning:
    """Watches each burst's lateness on the injected clock and logs the throttled warning."""

    def __init__(self, clock: Clock, sustained_s: float = SUSTAINED_S,
                 interval_s: float = WARNING_INTERVAL_S) -> None:
        self.clock = clock
        self.sustained_s = sustained_s
        self.interval_s = interval_s
        self.warnings = 0
        self._late_since: float | None = None
        self._worst_s = 0.0
        self._last_warning = -math.inf

    def observe(self, lateness_s: float) -> bool:
        """Record one burst's lateness (seconds; ≤ 0 on time); returns whether a warning line was written."""
        now = self.clock.now()
        if lateness_s <= 0.0:
            self._late_since = None
            return False
        if self._late_since is None:
            self._late_since, self._worst_s = now, 0.0
        self._worst_s = max(self._worst_s, lateness_s)
        if now - self._late_since < self.sustained_s or now - self._last_warning < self.interval_s:
            return False
        self._last_warning = now
        self.warnings += 1
        logger.warning("poses are running late: up to %.0f ms past their time for the last %.1f s (the machine "
                       "is busier than the settings allow); give them more time with --latency (quality waits "
                       "longest) or a larger --margin-ms, or less work with --steps 1",
                       self._worst_s * MS_PER_S, now - self._late_since)
        return True
