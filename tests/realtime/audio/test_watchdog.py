"""The stalled-device watchdog on explicit times: warn once, say when audio is back, give up after the timeout."""

import logging

import pytest

from gesturecast.errors import UserError
from gesturecast.realtime.audio.watchdog import StallWatchdog

LABEL = "input device 3 (USB Audio Device: Mic)"


def test_silence_warns_once_with_the_device_name_then_audio_is_back(caplog):
    watchdog = StallWatchdog(LABEL, now=100.0, timeout_s=10.0, warn_s=2.0)
    with caplog.at_level(logging.WARNING):
        for t in (100.5, 101.9, 102.0, 103.0, 105.0):
            watchdog.silence(t)
        assert watchdog.stalled
        watchdog.audio(106.0)
        watchdog.silence(106.5)
    assert not watchdog.stalled
    assert [r.getMessage() for r in caplog.records] == [
        f"no audio from {LABEL} for 2.0 s (stalled or suspended microphone?); waiting up to 10 s for it",
        f"audio from {LABEL} is back after 6.0 s without samples",
    ]


def test_silence_past_the_timeout_is_one_user_error_naming_the_device():
    watchdog = StallWatchdog(LABEL, now=0.0, timeout_s=3.0)
    watchdog.silence(2.9)
    with pytest.raises(UserError) as error:
        watchdog.silence(3.0)
    assert LABEL in str(error.value) and "--stall-timeout" in str(error.value) and "\n" not in str(error.value)


def test_audio_resets_the_timeout():
    watchdog = StallWatchdog(LABEL, now=0.0, timeout_s=3.0)
    for t in (1.0, 2.5, 4.0, 5.5):
        watchdog.audio(t)
        watchdog.silence(t + 2.9)


def test_a_timeout_shorter_than_the_warning_ends_without_a_warning(caplog):
    watchdog = StallWatchdog(LABEL, now=0.0, timeout_s=1.0)
    with caplog.at_level(logging.WARNING), pytest.raises(UserError):
        watchdog.silence(1.0)
    assert not caplog.records
