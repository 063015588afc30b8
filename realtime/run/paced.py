"""Paced frame feeds: a :class:`~gesturecast.realtime.run.stream.Stream`'s frames handed to the caller at their
presentation times, for programs that act on each pose when it is due (a robot, a game loop, an asyncio server).

The stream's release thread (the scheduler that also feeds the outputs) puts each frame into every open feed when
the frame is due; a feed ends when the stream is closed or stopped. :class:`FrameFeed` is read with ``for`` (it
blocks until the next frame is due), :class:`AsyncFrameFeed` with ``async for`` (it awaits without blocking the
event loop). A feed sees the frames released after it was opened, and keeps those its reader has not taken yet
until the stream ends.
"""

from __future__ import annotations

import asyncio
import queue
import threading
from collections.abc import AsyncIterator, Iterator

from gesturecast.frames import PoseFrame

_END = None  # put into a feed when its stream has ended


class FrameFeed:
    """Frames at their presentation times, read with ``for`` (blocking); opened by ``Stream.frames()``."""

    def __init__(self) -> None:
        self._queue: queue.SimpleQueue[PoseFrame | None] = queue.SimpleQueue()

    def put(self, frame: PoseFrame) -> None:
        """Called by the release thread when ``frame`` is due."""
        self._queue.put(frame)

    def end(self) -> None:
        """The stream has ended: iteration stops after the frames already released."""
        self._queue.put(_END)

    def __iter__(self) -> Iterator[PoseFrame]:
        while (frame := self._queue.get()) is not _END:
            yield frame


class AsyncFrameFeed:
    """Frames at their presentation times, read with ``async for``; opened by ``Stream.aframes()`` inside the
    event loop that reads it."""

    def __init__(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._queue: asyncio.Queue[PoseFrame | None] = asyncio.Queue()

    def put(self, frame: PoseFrame) -> None:
        """Called by the release thread when ``frame`` is due (handed to the event loop's thread)."""
        self._hand_over(frame)

    def end(self) -> None:
        self._hand_over(_END)

    def _hand_over(self, item: PoseFrame | None) -> None:
        try:
            self._loop.call_soon_threadsafe(self._queue.put_nowait, item)
        except RuntimeError:  # the event loop has closed: nobody reads this feed any more
            return

    async def __aiter__(self) -> AsyncIterator[PoseFrame]:
        while (frame := await self._queue.get()) is not _END:
            yield frame


class FeedSet:
    """The open feeds of one stream (thread-safe: opened by the caller, fed by the release thread)."""

    def __init__(self) -> None:
        self._feeds: list[FrameFeed | AsyncFrameFeed] = []
        self._lock = threading.Lock()
        self._ended = False

    def open(self, feed: FrameFeed | AsyncFrameFeed) -> FrameFeed | AsyncFrameFeed:
        with self._lock:
            if self._ended:
                feed.end()
            else:
                self._feeds.append(feed)
        return feed

    def put(self, frame: PoseFrame) -> None:
        with self._lock:
            feeds = list(self._feeds)
        for feed in feeds:
            feed.put(frame)

    def end(self) -> None:
        with self._lock:
            self._ended = True
            feeds, self._feeds = self._feeds, []
        for feed in feeds:
            feed.end()
