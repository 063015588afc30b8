"""``gesturecast serve``: many concurrent streams in one process, audio in and poses out over WebSocket.

Each WebSocket connection (``/stream/<id>``) is one stream with its own :class:`ServeStream`; all
streams' denoiser calls are batched through one shared session (:mod:`batched_denoiser`). The
asyncio server runs in its own thread (start / close); the protocol is in :mod:`serve_protocol` and
docs/serve.md. Listens on 127.0.0.1 unless told otherwise; beyond loopback a token is required
(``check_exposure``) and a stream starts only after a ``start`` message carrying it. Browser origins and
the wrong-token limit: :mod:`gesturecast.bridges.ws_access`.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import itertools
import json
import logging
import socket
import threading
from collections import deque
from contextlib import suppress
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

from websockets.asyncio.server import ServerConnection, broadcast
from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode

from gesturecast.bridges import ws_protocol
from gesturecast.bridges.control import WORDS_MESSAGE, decode_client_message, submit_control
from gesturecast.bridges.coords import coordinate_frame
from gesturecast.bridges.transport import ErrorThrottle
from gesturecast.bridges.ws_access import AccessPolicy, send_refusal
from gesturecast.bridges.ws_listener import ThreadedListener, private_listener
from gesturecast.controls import ControlError, control_schema
from gesturecast.message_rate import MessageRate, RateLimits
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.serve.heap import HeapTrimmer
from gesturecast.realtime.serve.protocol import (
    DEFAULT_AUDIO_FORMAT,
    MAX_AUDIO_MESSAGE_BYTES,
    decode_audio,
    hello,
    parse_start,
    started,
    stats_message,
    stream_id_from_path,
)
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.serve.shared_failures import shared_failures
from gesturecast.realtime.serve.stream import ServeStream, StreamConfig
from gesturecast.realtime.timing.clock import Clock

logger = logging.getLogger(__name__)

SERVE_DEFAULT_PORT = 8766
SERVE_PORT_FLAG = "--port"
STOP_TIMEOUT_S = 10.0
MAX_OUTGOING_MESSAGES = 64  # per connection, waiting for the event loop (drop-oldest beyond, counted)
SLOW_CLIENT_BUFFER_BYTES = 256 * 1024  # a client whose socket buffer holds more skips pose frames
START_TIMEOUT_S = 10.0  # a connection that neither starts nor sends audio within this is closed (1008)
MAX_UNSTARTED = 8  # connections waiting to start, besides the --max-streams started ones (more: the oldest goes)


class ServerFull(ControlError):
    """A start while every stream slot is taken: answered with an ``error``, then closed with 1013."""


@dataclass(frozen=True)
class ServeConfig:
    host: str = "127.0.0.1"
    port: int = SERVE_DEFAULT_PORT
    token: str | None = None
    max_streams: int = 16
    coordinate_frame: str = "internal"
    stream: StreamConfig = field(default_factory=StreamConfig)
    allow_origins: tuple[str, ...] = ()  # browser origins allowed to connect (ws_access)
    start_timeout_s: float = START_TIMEOUT_S  # from the hello to a start (or the first audio)
    max_unstarted: int = MAX_UNSTARTED  # connections not started yet (they hold no --max-streams slot)
    dealt: bool = False  # no port of its own: serve --workers' parent accepts and deals connections (:meth:`adopt`)
    token_failures: Path | None = None  # serve --workers: the wrong-token table all workers share (shared_failures)
    rate_limits: RateLimits = field(default_factory=RateLimits)  # per connection: control and words messages


def connection_counters(sender: LoopSender, rate: MessageRate) -> dict[str, int]:
    """What a connection did not deliver or apply (in its stream's stats)."""
    return {**sender.counters(), "rate_limited_messages": rate.refused}


class LoopSender:
    """Thread-safe, bounded hand-off of outgoing messages to one connection on the event loop."""

    def __init__(self, loop: asyncio.AbstractEventLoop, websocket: ServerConnection) -> None:
        self.loop = loop
        self.websocket = websocket
        self._pending: deque[bytes | str] = deque(maxlen=MAX_OUTGOING_MESSAGES)  # full: the oldest goes
        self._lock = threading.Lock()
        self._drain_scheduled = False
        self._closing: asyncio.Task | None = None
        self.outbox_drops = 0  # messages dropped (oldest first) while the event loop was behind
        self.slow_client_skips = 0  # pose frames not sent because the client's socket buffer was full

    def counters(self) -> dict[str, int]:
        """Messages this connection did not deliver (in the stream's stats)."""
        return {"outbox_drops": self.outbox_drops, "slow_client_skips": self.slow_client_skips}

    def send(self, message: bytes | str) -> None:
        with self._lock:
            if len(self._pending) == MAX_OUTGOING_MESSAGES:
                self.outbox_drops += 1
            self._pending.append(message)
            schedule, self._drain_scheduled = not self._drain_scheduled, True
        if schedule:
            self.loop.call_soon_threadsafe(self._drain)

    def close_when_sent(self) -> None:
        """Close the connection after everything sent so far (callbacks run in FIFO order)."""
        self.loop.call_soon_threadsafe(self._close)

    def _close(self) -> None:
        self._closing = self.loop.create_task(self.websocket.close())

    def _drain(self) -> None:
        with self._lock:
            messages = list(self._pending)
            self._pending.clear()
            self._drain_scheduled = False
        for message in messages:
            slow = self.websocket.transport.get_write_buffer_size() > SLOW_CLIENT_BUFFER_BYTES
            if slow and isinstance(message, bytes):  # pose frames are skipped for a slow client
                self.slow_client_skips += 1
            else:
                broadcast([self.websocket], message)


class StreamConnection:
    """One client's protocol state (event-loop thread): start, audio, control, end."""

    def __init__(self, server: GestureServer, websocket: ServerConnection, stream_id: str) -> None:
        self.server = server
        self.stream_id = stream_id
        self.websocket = websocket
        self.sender = LoopSender(asyncio.get_running_loop(), websocket)
        self.stream: ServeStream | None = None
        self.holds_slot = False  # from the moment a start is accepted: counts against --max-streams
        self.evicted = False  # closed unstarted to make room for a newer connection (GestureServer._make_room)
        self.audio_format = DEFAULT_AUDIO_FORMAT
        self.rate = MessageRate(server.clock.now, server.config.rate_limits)  # its control and words messages
        self._closed = False

    async def answer(self, message: bytes | str) -> None:
        """Reply to one message; a refused one gets an ``error`` (and a wrong token also a close)."""
        try:
            reply = await self._reply_to(message)
        except ControlError as error:
            self.server.errors.report(ControlError(f"stream {self.stream_id}: {error}"))
            await send_refusal(self.websocket, error)
            if isinstance(error, ServerFull):
                await self.websocket.close(CloseCode.TRY_AGAIN_LATER, str(error))
            return
        if reply is not None:
            await self.websocket.send(reply)

    async def _reply_to(self, message: bytes | str) -> str | None:
        if isinstance(message, bytes):
            return await self._audio(message)
        return await self._command(decode_client_message(message))

    async def _command(self, message: dict) -> str | None:
        kind = message["type"]
        if kind == "start":
            return await self._start(message)
        if self.stream is None:
            raise ControlError(f"no stream yet: send audio or a start message before {kind!r}")
        if kind in ("control", WORDS_MESSAGE):  # a words message is a control holding only words
            return await self._control({**message, "type": "control"})
        if kind == "end":
            self.stream.end()
            return None
        raise ControlError(f"unknown message type {kind!r}; use start, control, words or end (audio: binary)")

    async def _control(self, message: dict) -> str:
        """Checked against the connection's rate, then acknowledged only once the session has resolved its styles
        (off the event loop)."""
        return await submit_control(message, self.stream.session.controls.submit, self.rate)

    async def _start(self, message: dict) -> str:
        if self.stream is not None:
            raise ControlError("the stream has already started")
        self.server.access.verify_token(self.websocket, message)
        options = parse_start(message)
        self.server.claim_slot(self)
        try:
            session = await asyncio.to_thread(self.server.sessions.session, options)
        except BaseException:
            self.holds_slot = False
            raise
        self.audio_format = options.audio_format
        self.stream = ServeStream(self.stream_id, session, self.server.clock, self.sender.send, self.server.coords,
                                  self.server.config.stream, on_finished=self.sender.close_when_sent,
                                  # not a method of the connection: the stream must not hold it (no reference cycle,
                                  # so a closed stream's session is freed at once)
                                  delivery_counters=partial(connection_counters, self.sender, self.rate)).start()
        logger.info("stream %s started (%s)", self.stream_id, session.controls.describe())
        return started(self.stream_id, session.controls.describe(), self.audio_format, session.budget.total_ms)

    async def _audio(self, data: bytes) -> str | None:
        reply = None
        if self.stream is None:
            if self.server.access.token_required:
                raise ControlError("this server needs a token: send {\"type\": \"start\", \"token\": ...} first")
            reply = await self._start({"type": "start"})
        samples = decode_audio(data, self.audio_format)
        self.stream.feed(samples, self.server.clock.now())
        return reply

    async def close(self) -> dict | None:
        """Stop the stream and record its stats, once; returns them (None before a start, or when already closed)."""
        if self.stream is None or self._closed:
            return None
        self._closed = True
        await asyncio.to_thread(self.stream.stop)
        stats = self.stream.stats()
        logger.info("stream %s closed: %s", self.stream_id, json.dumps(stats))
        self.server.remember(stats)
        return stats

    async def go_away(self) -> None:
        """The server is stopping: the stream ends now, and its client gets the stats before the 1001 close."""
        stats = await self.close()
        if stats is not None:
            with suppress(ConnectionClosed):
                await self.websocket.send(stats_message(stats))


class GestureServer:
    """Owns the WebSocket server thread and the stream sessions (closed together by :meth:`close`)."""

    def __init__(self, sessions: StreamSessions, clock: Clock, config: ServeConfig | None = None) -> None:
        self.config = config or ServeConfig()
        self.access = AccessPolicy(self.config.host, self.config.token, self.config.allow_origins, clock.now,
                                   shared_failures(self.config.token_failures, clock.now))
        self.sessions = sessions
        self.clock = clock
        self.coords = coordinate_frame(self.config.coordinate_frame)
        self.errors = ErrorThrottle("serve: client message rejected")
        self.finished: deque[dict] = deque(maxlen=self.config.max_streams)  # stats of recently closed streams
        self._connections: dict[str, StreamConnection] = {}
        self._ids = itertools.count(1)
        self.heap = HeapTrimmer.for_this_platform()  # freed heap back to the OS after a stream closes (glibc)
        self._listener = ThreadedListener(self.config.host, self.config.port, "gesturecast-serve", STOP_TIMEOUT_S,
                                          port_flag=SERVE_PORT_FLAG)

    # ---- lifecycle (caller's thread) ----
    def start(self) -> GestureServer:
        self._listener.start(self._handle, private_listener() if self.config.dealt else None,
                             process_request=self.access.process_request, max_size=MAX_AUDIO_MESSAGE_BYTES)
        logger.info("serving streams on %s (at most %d)", self.url, self.config.max_streams)
        return self

    @property
    def port(self) -> int:
        """The listening port (the bound one once started, also when ``config.port`` is 0)."""
        return self._listener.port

    @property
    def url(self) -> str:
        return f"ws://{self.config.host}:{self.port}/stream/"

    def adopt(self, connection: socket.socket) -> concurrent.futures.Future:
        """Serve a connection the ``serve --workers`` parent accepted; the future is done when it has closed."""
        return self._listener.adopt(connection)

    def active_streams(self) -> int:
        """Open connections, started or not."""
        return len(self._connections)

    def started_streams(self) -> int:
        """Connections whose start was accepted: they hold the ``max_streams`` slots."""
        return sum(connection.holds_slot for connection in self._connections.values())

    def claim_slot(self, connection: StreamConnection) -> None:
        """Give a starting connection one of the ``max_streams`` slots; ServerFull (1013) when none is free."""
        if connection.evicted:
            raise ServerFull("this connection waited longest to start and is being closed to make room")
        if self.started_streams() >= self.config.max_streams:
            raise ServerFull(f"server full ({self.config.max_streams} streams)")
        connection.holds_slot = True

    def remember(self, stats: dict) -> None:
        self.finished.append(stats)

    def close(self) -> None:
        """Stop serving (Ctrl-C, SIGTERM): every open stream ends at once and its client gets the stream's stats,
        then each connection is closed with 1001 (going away) and the sessions are freed."""
        self._send_final_stats()
        self._listener.close()
        self.sessions.close()

    def _send_final_stats(self) -> None:
        """Run :meth:`StreamConnection.go_away` for every connection, bounded by ``STOP_TIMEOUT_S``."""
        if not self._listener.loop.is_running():
            return
        future = asyncio.run_coroutine_threadsafe(self._going_away(), self._listener.loop)
        try:
            future.result(STOP_TIMEOUT_S)
        except concurrent.futures.TimeoutError:
            future.cancel()
            logger.warning("the streams' final stats took over %.0f s; closing without them", STOP_TIMEOUT_S)

    async def _going_away(self) -> None:
        connections = list(self._connections.values())
        await asyncio.gather(*(connection.go_away() for connection in connections), return_exceptions=True)

    # ---- event-loop thread ----
    def _hello(self, stream_id: str) -> str:
        styles = tuple(self.sessions.bundle.styles.labels)
        viewer = ws_protocol.hello_message(CANONICAL_WITH_HANDS, self.coords, self.config.stream.output_fps,
                                           self.sessions.defaults.style_prompt().value, styles, control_schema(),
                                           self.access.token_required,
                                           body_parts=tuple(self.sessions.bundle.part_channels),
                                           gestures=self.sessions.gesture_names)
        return hello(viewer, stream_id, self.sessions.budget.total_ms)

    async def _refuse(self, websocket: ServerConnection, reason: str, code: CloseCode) -> None:
        await websocket.send(ws_protocol.error_message(reason))
        await websocket.close(code, reason[:100])

    async def _handle(self, websocket: ServerConnection) -> None:
        try:
            stream_id = stream_id_from_path(websocket.request.path, f"stream-{next(self._ids)}")
        except ControlError as error:
            await self._refuse(websocket, str(error), CloseCode.POLICY_VIOLATION)
            return
        refusal = self._full_reason()
        if refusal is not None:
            await self._refuse(websocket, refusal, CloseCode.TRY_AGAIN_LATER)
            return
        if stream_id in self._connections:
            await self._refuse(websocket, f"stream id {stream_id!r} is in use", CloseCode.POLICY_VIOLATION)
            return
        await self._serve_stream(websocket, stream_id)

    def _full_reason(self) -> str | None:
        """Why a new connection is refused (1013), or None: every stream slot is taken by a started stream."""
        if self.started_streams() >= self.config.max_streams:
            return f"server full ({self.config.max_streams} streams)"
        return None

    def _make_room(self) -> None:
        """With ``max_unstarted`` connections waiting to start, the one that has waited longest is closed (1013), so
        idle connections never keep a new client out."""
        waiting = [c for c in self._connections.values() if not (c.holds_slot or c.evicted)]
        if len(waiting) >= self.config.max_unstarted:
            reason = f"server busy: {len(waiting)} connections were waiting to start and this one waited longest"
            waiting[0].evicted = True  # it can no longer start; its handler ends when the close is done
            asyncio.create_task(self._refuse_quietly(waiting[0].websocket, reason, CloseCode.TRY_AGAIN_LATER))

    async def _refuse_quietly(self, websocket: ServerConnection, reason: str, code: CloseCode) -> None:
        """:meth:`_refuse` on a connection that may be gone already."""
        with suppress(ConnectionClosed):
            await self._refuse(websocket, reason, code)

    async def _close_if_not_started(self, connection: StreamConnection) -> None:
        """The pre-start timeout: a connection that has not started after ``start_timeout_s`` is closed (1008)."""
        await asyncio.sleep(self.config.start_timeout_s)
        if not connection.holds_slot:
            reason = f"no start message or audio within {self.config.start_timeout_s:g} s"
            await self._refuse_quietly(connection.websocket, reason, CloseCode.POLICY_VIOLATION)

    async def _serve_stream(self, websocket: ServerConnection, stream_id: str) -> None:
        self._make_room()
        connection = self._connections[stream_id] = StreamConnection(self, websocket, stream_id)
        deadline = asyncio.create_task(self._close_if_not_started(connection))
        try:
            await websocket.send(self._hello(stream_id))
            async for message in websocket:
                await connection.answer(message)
        except ConnectionClosed:
            logger.debug("stream %s: client went away", stream_id)
        finally:
            deadline.cancel()
            connection.holds_slot = False  # the client has gone or the stream has ended: a new one may start now
            try:
                await connection.close()  # records the stream's stats before it stops counting as active
            finally:
                del self._connections[stream_id]  # the stream is freed (reference counting) as this handler returns
                self.heap.request()
