"""Give freed heap back to the operating system after a stream closes (glibc only; elsewhere a no-op).

A closed stream frees its session at once (no reference cycles keep it), but glibc's allocator keeps the freed
chunks in its per-thread arenas, and many streams' threads make many arenas: RSS stays at its high-water mark.
``malloc_trim(0)`` returns the free pages of every arena. It walks the heap and briefly holds each arena's lock,
so :class:`HeapTrimmer` runs it off the event loop and at most once per ``min_interval_s`` (the last close in a
burst is always followed by one trim). Where there is no glibc (macOS, Windows, musl without the symbol) nothing
is called.
"""

from __future__ import annotations

import asyncio
import ctypes
import ctypes.util
import logging
import time
from collections.abc import Callable

logger = logging.getLogger(__name__)

MIN_TRIM_INTERVAL_S = 1.0


def glibc_malloc_trim() -> Callable[[], None] | None:
    """``malloc_trim(0)`` of the C library when it has one (glibc), else None."""
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    try:
        trim = getattr(ctypes.CDLL(name), "malloc_trim", None)
    except OSError:
        return None
    if trim is None:
        return None
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    return lambda: trim(0)


class HeapTrimmer:
    """:meth:`request` (event-loop thread) after a stream closes: one trim soon, rate-limited, in a worker thread."""

    def __init__(self, trim: Callable[[], None] | None = None, min_interval_s: float = MIN_TRIM_INTERVAL_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.trim = trim
        self.min_interval_s = min_interval_s
        self.clock = clock
        self.trims = 0  # trims done (for tests and logs)
        self._last = -float("inf")
        self._pending = False
        self._task: asyncio.Task | None = None  # the running trim (held: the loop keeps only weak references)

    @classmethod
    def for_this_platform(cls) -> HeapTrimmer:
        return cls(glibc_malloc_trim())

    def request(self) -> None:
        """Schedule a trim ``min_interval_s`` after the previous one at the earliest; one pending at a time."""
        if self.trim is None or self._pending:
            return
        self._pending = True
        delay = max(0.0, self._last + self.min_interval_s - self.clock())
        asyncio.get_running_loop().call_later(delay, self._start)

    def _start(self) -> None:
        self._task = asyncio.ensure_future(self._run())

    async def _run(self) -> None:
        self._pending = False
        self._last = self.clock()
        try:
            await asyncio.to_thread(self.trim)
        except Exception:  # never let memory housekeeping break a server
            logger.debug("malloc_trim failed", exc_info=True)
        self.trims += 1
