"""The live one-line terminal status: latency percentiles, deadline misses, audio skipped, style.

Rewritten in place with a carriage return when the stream is a TTY; silent otherwise (logs and pipes
get the final summary instead of hundreds of partial lines).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import TextIO

from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.ladder import DegradationLadder
from gesturecast.realtime.timing.latency import LatencyBudget, LatencyStats
from gesturecast.realtime.timing.scheduler import STAGE_END_TO_END, SchedulerStats

DEFAULT_UPDATE_INTERVAL_S = 0.25
RECENT_SECONDS = 10.0  # the status line's percentiles cover the frames sent in about the last 10 s
MAX_STYLE_CHARS = 24


@dataclass(frozen=True)
class StatusSnapshot:
    """What the status line shows (latencies in ms; NaN = not measured yet)."""

    latency_budget_ms: float
    end_to_end_p50_ms: float
    end_to_end_p95_ms: float
    deadline_misses: int
    audio_skipped: int  # microphone samples skipped ahead on purpose (the engine fell too far behind)
    late_releases: int = 0
    style: str = ""
    speaking: bool = False
    rung: int = 0  # the degradation ladder's rung (0: full work)
    bursts_per_rung: tuple[int, ...] = ()  # () when the run does not adapt


def build_snapshot(
    budget: LatencyBudget,
    stats: LatencyStats,
    scheduler_stats: SchedulerStats,
    output_fps: float,
    audio_skipped: int,
    style: str = "",
    speaking: bool = False,
    ladder: DegradationLadder | None = None,
) -> StatusSnapshot:
    """The current status: end-to-end percentiles over the output frames of the last :data:`RECENT_SECONDS`
    (at ``output_fps``: 60 fps sends twice as many frames per second as 30 fps)."""
    recent_frames = round(RECENT_SECONDS * output_fps)
    p50, p95 = stats.percentiles_ms(STAGE_END_TO_END, (50.0, 95.0), last=recent_frames)
    rung, counts = (0, ()) if ladder is None else (ladder.rung, tuple(ladder.counts))
    return StatusSnapshot(budget.total_ms, p50, p95, scheduler_stats.deadline_misses, audio_skipped,
                          scheduler_stats.late_releases, style, speaking, rung, counts)


def _ms(value: float) -> str:
    return "--" if math.isnan(value) else f"{value:.0f}"


def format_status(snapshot: StatusSnapshot) -> str:
    """One line, e.g. ``L 500 ms | e2e p50 480 p95 495 ms | misses 0 late 0 | rung 1 (412/9/0) | audio skipped 0 |
    style happy | speaking`` (misses: late computation; late: frames released more than half a frame after their
    time; rung: the degradation ladder's, with the bursts generated at each rung; left out when the run does not
    adapt)."""
    style = snapshot.style if len(snapshot.style) <= MAX_STYLE_CHARS else snapshot.style[: MAX_STYLE_CHARS - 1] + "…"
    parts = [
        f"L {snapshot.latency_budget_ms:.0f} ms",
        f"e2e p50 {_ms(snapshot.end_to_end_p50_ms)} p95 {_ms(snapshot.end_to_end_p95_ms)} ms",
        f"misses {snapshot.deadline_misses} late {snapshot.late_releases}",
        *_rung(snapshot),
        f"audio skipped {snapshot.audio_skipped}",
        f"style {style or '-'}",
        "speaking" if snapshot.speaking else "silent",
    ]
    return " | ".join(parts)


def _rung(snapshot: StatusSnapshot) -> list[str]:
    if not snapshot.bursts_per_rung:
        return []
    return [f"rung {snapshot.rung} ({'/'.join(str(count) for count in snapshot.bursts_per_rung)})"]


class StatusLine:
    """Writes :func:`format_status` lines in place on a TTY, at most once per ``update_interval_s``."""

    def __init__(
        self, clock: Clock, stream: TextIO | None = None, update_interval_s: float = DEFAULT_UPDATE_INTERVAL_S
    ) -> None:
        self.clock = clock
        self.stream = sys.stdout if stream is None else stream
        self.update_interval_s = update_interval_s
        self.enabled = self.stream.isatty()
        self._last_update = -math.inf
        self._last_width = 0

    def update(self, snapshot: StatusSnapshot) -> bool:
        """Redraw the line if enabled and the interval has passed; returns whether it was drawn."""
        now = self.clock.now()
        if not self.enabled or now - self._last_update < self.update_interval_s:
            return False
        self._last_update = now
        line = format_status(snapshot)
        padding = " " * max(0, self._last_width - len(line))  # erase the tail of a longer previous line
        self.stream.write("\r" + line + padding)
        self.stream.flush()
        self._last_width = len(line)
        return True

    def close(self) -> None:
        """End the status line with a newline so later output starts on a fresh line."""
        if self.enabled and self._last_width:
            self.stream.write("\n")
            self.stream.flush()
            self._last_width = 0
