"""What a closed ``serve`` stream leaves behind: nothing that waits for the garbage collector, and freed heap handed
back to the OS (rate-limited ``malloc_trim``). RSS itself is measured by ``gesturecast bench serve --churn``."""

import asyncio
import ctypes.util
import gc
import weakref
from contextlib import contextmanager

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.serve import heap
from gesturecast.realtime.serve.heap import HeapTrimmer, glibc_malloc_trim
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings
from gesturecast.tools.bench.serve_client import stream_audio

DEFAULTS = Settings(steps=2, guidance=1.5, seed=0, audio_guidance=1.0, smoothing=0, gestures=None)  # L: δa, 100 ms
TIMEOUT_S = 60.0
CHUNK = 4000


@contextmanager
def recording_server(bundle):
    """A server whose sessions are recorded as weak references as they are made."""
    clock = MonotonicClock()
    sessions = StreamSessions(DEFAULTS, bundle, clock, max_streams=4)
    made = []
    make = sessions.session

    def session(options):
        made.append(weakref.ref(made_session := make(options)))
        return made_session

    sessions.session = session
    server = GestureServer(sessions, clock, ServeConfig(port=0, max_streams=4)).start()
    try:
        yield server, made
    finally:
        server.close()


def test_a_closed_stream_is_freed_without_the_garbage_collector(bundle, shared_data, wait_until):
    """With the collector off, the sessions of closed streams (KV caches, decoder session, statistics rings) are
    freed by reference counting alone: no stream ↔ scheduler cycle keeps them until a full collection."""
    speech = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: SAMPLE_RATE // 2]

    async def streams(url):
        return await asyncio.gather(*(stream_audio(f"{url}freed-{i}", speech, CHUNK, paced=False) for i in range(3)))

    gc.collect()
    gc.disable()
    try:
        with recording_server(bundle) as (server, made):
            results = asyncio.run(asyncio.wait_for(streams(server.url), TIMEOUT_S))
            assert wait_until(lambda: server.active_streams() == 0)
            freed = wait_until(lambda: all(ref() is None for ref in made))
    finally:
        gc.enable()
    assert [r.errors for r in results] == [[], [], []] and len(made) == 3
    assert freed, "a closed stream's session waits for the garbage collector"


async def until(predicate, limit_s: float = 10.0) -> None:
    """Poll ``predicate`` on the event loop (a bound on hanging, not a speed assertion)."""
    for _ in range(int(limit_s / 0.01)):
        if predicate():
            return
        await asyncio.sleep(0.01)


def test_heap_trims_are_rate_limited_and_one_follows_the_last_close():
    calls = []
    trimmer = HeapTrimmer(lambda: calls.append(1), min_interval_s=0.1)

    async def closes():
        for _ in range(5):  # a burst of closes: one trim
            trimmer.request()
        await until(lambda: trimmer.trims == 1)
        trimmer.request()  # soon after a trim: one more, once the interval has passed
        trimmer.request()
        await until(lambda: trimmer.trims == 2)
        await asyncio.sleep(0.3)  # nothing else was asked for
        return trimmer.trims

    assert asyncio.run(asyncio.wait_for(closes(), TIMEOUT_S)) == 2 and len(calls) == 2


def test_malloc_trim_is_called_only_where_the_c_library_has_it(monkeypatch):
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)  # e.g. Windows
    assert glibc_malloc_trim() is None
    HeapTrimmer(glibc_malloc_trim()).request()  # a no-op, also outside an event loop

    class NoTrim:  # a C library without the symbol (macOS, musl)
        def __init__(self, name):
            pass

    monkeypatch.setattr(ctypes.util, "find_library", lambda name: "libc.dylib")
    monkeypatch.setattr(heap.ctypes, "CDLL", NoTrim)
    assert glibc_malloc_trim() is None
