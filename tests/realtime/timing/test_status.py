"""The status line: formatted content, in-place redraw on a TTY only, throttled on the injected clock."""

import io

import pytest

from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.ladder import DegradationLadder
from gesturecast.realtime.timing.latency import LatencyBudget, LatencyStats
from gesturecast.realtime.timing.scheduler import STAGE_END_TO_END, SchedulerStats
from gesturecast.realtime.timing.status import RECENT_SECONDS, StatusLine, StatusSnapshot, build_snapshot, format_status


class FakeTty(io.StringIO):
    def isatty(self) -> bool:
        return True


SNAPSHOT = StatusSnapshot(500.0, 481.4, 497.6, 2, 1, late_releases=5, style="happy", speaking=True)


def test_format_shows_every_field():
    line = format_status(SNAPSHOT)
    assert line == "L 500 ms | e2e p50 481 p95 498 ms | misses 2 late 5 | audio skipped 1 | style happy | speaking"


def test_an_adapting_run_shows_its_rung_and_the_bursts_at_each_rung():
    ladder = DegradationLadder(3)
    for share in (0.2, 1.5, 0.3):
        ladder.observe(share)
    snapshot = build_snapshot(LatencyBudget(4, 8, 100.0), LatencyStats(FakeClock()), SchedulerStats(), 30.0, 0,
                              ladder=ladder)
    assert "| misses 0 late 0 | rung 1 (2/1/0) | audio skipped 0 |" in format_status(snapshot)


def test_unmeasured_latency_and_long_style_are_readable():
    snapshot = StatusSnapshot(500.0, float("nan"), float("nan"), 0, 0, style="x" * 80)
    line = format_status(snapshot)
    assert "e2e p50 -- p95 -- ms" in line
    assert len(line) < 120


def test_tty_redraws_in_place_throttled_and_closes_with_newline():
    clock, stream = FakeClock(), FakeTty()
    status = StatusLine(clock, stream, update_interval_s=0.25)
    assert status.update(SNAPSHOT)
    assert not status.update(SNAPSHOT)  # too soon
    clock.advance(0.3)
    shorter = StatusSnapshot(500.0, 1.0, 2.0, 0, 0)
    assert status.update(shorter)
    status.close()
    text = stream.getvalue()
    assert text.count("\r") == 2 and text.endswith("\n")
    second = text.split("\r")[2].rstrip("\n")
    assert len(second) == len(format_status(SNAPSHOT))  # padded to erase the longer previous line


def test_non_tty_writes_nothing():
    stream = io.StringIO()
    status = StatusLine(FakeClock(), stream)
    assert not status.update(SNAPSHOT)
    status.close()
    assert stream.getvalue() == ""


@pytest.mark.parametrize("output_fps", [30.0, 60.0])
def test_snapshot_uses_recent_end_to_end_samples_and_scheduler_counters(output_fps):
    """The percentiles cover the last RECENT_SECONDS of *output* frames: at 60 fps that is twice the frames."""
    stats = LatencyStats(FakeClock())
    recent = round(RECENT_SECONDS * output_fps)
    for _ in range(1000):
        stats.record(STAGE_END_TO_END, 2.0)  # an old bad patch
    for _ in range(recent - 1):
        stats.record(STAGE_END_TO_END, 0.5)
    stats.record(STAGE_END_TO_END, 2.0)  # one bad frame within the window is the p100 only, never the p95
    counters = SchedulerStats(deadline_misses=3, late_releases=7)
    snapshot = build_snapshot(LatencyBudget(4, 8, 100.0), stats, counters, output_fps, 4, "calm")
    assert snapshot.end_to_end_p95_ms == pytest.approx(500.0)
    assert (snapshot.latency_budget_ms, snapshot.deadline_misses, snapshot.audio_skipped) == (500.0, 3, 4)
    assert snapshot.late_releases == 7
    assert "style calm" in format_status(snapshot)
