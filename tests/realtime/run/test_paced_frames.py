"""The paced forms of ``Stream`` output (``frames()``, ``aframes()``, ``on_frame``) hand each pose over at its
presentation time, measured on an injected clock that moves only when the test moves it."""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Callable

import pytest

import gesturecast
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.realtime.run.stream import Stream

SECONDS = 2
REAL_WAIT_S = 30.0  # how long the test waits (real time) for a thread to get where it must: only a failure waits


class SteppedClock:
    """A clock that stands still until :meth:`advance_to`; its waits block (in real time) until then, and it
    records the times the release thread is waiting for."""

    def __init__(self) -> None:
        self._now = 0.0
        self._changed = threading.Condition()
        self.waiting_for: list[float] = []

    def now(self) -> float:
        with self._changed:
            return self._now

    def advance_to(self, t: float) -> None:
        with self._changed:
            self._now = max(self._now, t)
            self._changed.notify_all()

    def sleep_until(self, t: float) -> None:
        with self._changed:
            self._changed.wait_for(lambda: self._now >= t)

    def wait_until(self, t: float, event: threading.Event) -> bool:
        with self._changed:
            self.waiting_for.append(t)
            while self._now < t and not event.is_set():
                self._changed.wait(0.001)  # the event cannot notify this condition: look again soon
            return event.is_set()


def wait_for(condition: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + REAL_WAIT_S
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting until {what}"
        time.sleep(0.0005)


def read_in_thread(form: str, stream: Stream, record: Callable) -> threading.Thread:
    """A thread reading ``stream`` with ``for`` (form "iterator") or ``async for`` ("async"), recording each frame;
    the feed is open when this returns."""
    opened = threading.Event()

    def iterate() -> None:
        feed = stream.frames()
        opened.set()
        for frame in feed:
            record(frame)

    async def iterate_async() -> None:
        feed = stream.aframes()
        opened.set()
        async for frame in feed:
            record(frame)

    thread = threading.Thread(target=iterate if form == "iterator" else lambda: asyncio.run(iterate_async()))
    thread.start()
    wait_for(opened.is_set, "the feed is open")
    return thread


@pytest.mark.parametrize("form", ["iterator", "async", "callback"])
def test_each_pose_is_handed_over_at_its_presentation_time(form):
    clock = SteppedClock()
    received: list = []  # (frame, the clock's time when it arrived)

    def record(frame) -> None:
        received.append((frame, clock.now()))

    stream = Stream(gesturecast.Settings(latency="low"), clock=clock, warm=False,
                    on_frame=record if form == "callback" else None)
    reader = None if form == "callback" else read_in_thread(form, stream, record)
    pushed = stream.push(load_audio(PACKAGED_SAMPLE)[: SECONDS * SAMPLE_RATE])  # computed now, at t = 0
    assert len(pushed) > SECONDS * 20 and all(frame.presentation_time > 0.0 for frame in pushed)
    for index, frame in enumerate(pushed):
        due = frame.presentation_time
        wait_for(lambda: due in clock.waiting_for, f"frame {index} is waited for")  # noqa: B023
        assert len(received) == index, f"frame {index} was handed over before {due:.3f} s"
        clock.advance_to(due)
        wait_for(lambda: len(received) > index, f"frame {index} is handed over")  # noqa: B023
        assert received[index] == (frame, due)
    closing = threading.Thread(target=stream.close)
    closing.start()
    deadline = time.monotonic() + REAL_WAIT_S
    while closing.is_alive() and time.monotonic() < deadline:  # time runs on until the last pose is released
        clock.advance_to(clock.now() + 0.1)
        closing.join(0.001)
    if reader is not None:
        reader.join(REAL_WAIT_S)
        assert not reader.is_alive(), "the feed did not end when the stream closed"
    assert all(arrived >= frame.presentation_time for frame, arrived in received)
    assert len(received) > len(pushed)  # the look-ahead's last poses, released by close()
