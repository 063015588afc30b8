"""The status line: formatted content, in-place redraw on a TTY only, throttled on the injected clock."""

import io

from gesturecast.realtime.clock import FakeClock
from gesturecast.realtime.status import StatusLine, StatusSnapshot, format_status


class FakeTty(io.StringIO):
    def isatty(self) -> bool:
        return True


SNAPSHOT = StatusSnapshot(500.0, 481.4, 497.6, 2, 1, style="happy", speaking=True)


def test_format_shows_every_field():
    line = format_status(SNAPSHOT)
    assert line == "L 500 ms | e2e p50 481 p95 498 ms | misses 2 | audio drops 1 | style happy | speaking"


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
