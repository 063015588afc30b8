"""The injected clocks: FakeClock is monotonic and never waits; MonotonicClock really sleeps forward."""

import pytest

from gesturecast.realtime.timing.clock import Clock, FakeClock, MonotonicClock


def test_fake_clock_advances_and_sleeps_by_jumping():
    clock = FakeClock(start=10.0)
    assert clock.now() == 10.0
    clock.advance(0.5)
    assert clock.now() == 10.5
    clock.sleep_until(12.0)
    assert clock.now() == 12.0
    clock.sleep_until(11.0)  # already past: no change, never backwards
    assert clock.now() == 12.0


def test_fake_clock_refuses_to_go_back():
    with pytest.raises(ValueError):
        FakeClock().advance(-0.1)


def test_both_clocks_satisfy_the_protocol():
    assert isinstance(FakeClock(), Clock)
    assert isinstance(MonotonicClock(), Clock)


def test_monotonic_clock_past_deadline_returns_without_going_back():
    clock = MonotonicClock()
    before = clock.now()
    clock.sleep_until(before - 1.0)
    assert clock.now() >= before
