"""PortAudio stream helpers: capture times from ADC timestamps, and closing a stream within a bound."""

import threading

import pytest

from gesturecast.realtime.audio.portaudio import advancing_adc_time, capture_time, close_stream

RATE = 48000


@pytest.mark.parametrize(
    ("adc", "current", "expected"),
    [
        (50.0, 50.12, 10.0 - 0.12),  # ADC time given: the block was captured 120 ms before the callback
        (0.0, 50.12, 10.0 - 480 / RATE),  # host API without ADC times: the block ended now
        (50.2, 50.12, 10.0 - 480 / RATE),  # an ADC time after the callback's time is not believed
    ],
)
def test_capture_time_maps_portaudio_time_onto_the_callers_clock(adc, current, expected):
    assert capture_time(10.0, adc, current, 480, RATE) == pytest.approx(expected)


def test_an_adc_time_that_does_not_advance_is_not_believed():
    assert advancing_adc_time(50.2, 50.1) == 50.2
    assert advancing_adc_time(50.1, 50.1) == 0.0  # repeated: the block is timed by its arrival instead
    assert advancing_adc_time(49.0, 50.1) == 0.0  # went back
    assert advancing_adc_time(0.0, 0.0) == 0.0  # a host API without ADC times stays untimed


class RecordingStream:
    """Stands in for a sounddevice stream only to record calls; the real one runs in test_live_microphone."""

    def __init__(self, abort_blocks: bool = False) -> None:
        self.calls: list[str] = []
        self.release = threading.Event()
        self.abort_blocks = abort_blocks

    def stop(self) -> None:
        self.calls.append("stop")

    def abort(self) -> None:
        self.calls.append("abort")
        if self.abort_blocks:
            self.release.wait()

    def close(self) -> None:
        self.calls.append("close")


def test_close_stream_aborts_and_closes_but_never_stops():
    stream = RecordingStream()
    assert close_stream(stream, bound_s=5.0)
    assert stream.calls == ["abort", "close"]


def test_close_stream_gives_up_after_the_bound_when_portaudio_blocks(caplog):
    stream = RecordingStream(abort_blocks=True)
    try:
        assert not close_stream(stream, bound_s=0.05)
    finally:
        stream.release.set()
    assert "did not close within 0.1 s" in caplog.text
