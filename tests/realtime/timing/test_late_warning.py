"""The late warning: one line once frames stay late for a moment, then at most one per interval (fake clock)."""

import logging

from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.late_warning import LateWarning

BURST_S = 0.133  # one latent of 4 frames at 30 fps


def lines_over(warning: LateWarning, clock: FakeClock, seconds: float, lateness_s: float) -> list[bool]:
    """One burst every BURST_S for ``seconds``, each ``lateness_s`` late; whether each wrote a line."""
    written = []
    for _ in range(round(seconds / BURST_S)):
        written.append(warning.observe(lateness_s))
        clock.advance(BURST_S)
    return written


def test_a_moment_of_lateness_says_nothing():
    clock = FakeClock()
    warning = LateWarning(clock, sustained_s=1.0, interval_s=10.0)
    assert not any(lines_over(warning, clock, 0.8, 0.2) + lines_over(warning, clock, 0.2, -0.05) * 20)
    assert warning.warnings == 0


def test_staying_late_writes_one_line_with_the_lateness_and_what_to_do(caplog):
    clock = FakeClock()
    warning = LateWarning(clock, sustained_s=1.0, interval_s=10.0)
    with caplog.at_level(logging.WARNING, logger="gesturecast.realtime.timing.late_warning"):
        written = lines_over(warning, clock, 2.0, 0.25)
    assert sum(written) == 1 and written.index(True) == 8  # the first burst 1 s after the lateness began
    (record,) = caplog.records
    assert "250 ms" in record.getMessage()
    assert all(flag in record.getMessage() for flag in ("--latency", "--margin-ms", "--steps"))


def test_while_it_lasts_at_most_one_line_every_interval():
    clock = FakeClock()
    warning = LateWarning(clock, sustained_s=1.0, interval_s=10.0)
    written = lines_over(warning, clock, 35.0, 0.1)
    assert sum(written) == 4  # at 1 s, 11 s, 21 s, 31 s
    times = [index * BURST_S for index, line in enumerate(written) if line]
    assert all(later - earlier >= 10.0 for earlier, later in zip(times, times[1:], strict=False))


def test_a_new_episode_soon_after_a_warning_waits_for_the_interval():
    clock = FakeClock()
    warning = LateWarning(clock, sustained_s=1.0, interval_s=10.0)
    assert sum(lines_over(warning, clock, 1.5, 0.1)) == 1
    lines_over(warning, clock, 1.0, 0.0)  # on time again
    assert sum(lines_over(warning, clock, 3.0, 0.1)) == 0  # late again, but within 10 s of the last line
    assert sum(lines_over(warning, clock, 8.0, 0.1)) == 1
