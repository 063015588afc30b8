"""WebSocket stream + browser viewer on one port (websockets asyncio server in its own thread).

On connect a client receives the JSON hello (:func:`ws_protocol.hello_message`), then one
binary frame per PoseFrame, or JSON frames after sending ``{"type": "subscribe", "format":
"json"}``. A style change is announced as ``{"type": "style", ...}``. Frames go out with
``broadcast()``; a client whose socket write buffer is above ``slow_client_buffer_bytes`` is
skipped for that frame (counted), so nothing is buffered without bound.

Clients may send control messages (:mod:`control`); valid ones go to ``on_control`` as typed controls,
invalid ones get ``{"type": "error"}`` back and one log line. Listens on 127.0.0.1 unless told
otherwise; beyond loopback a token is required for control messages. Who may connect (browser
origins, wrong-token limit) is :mod:`ws_access`.
"""

from __future__ import annotations

import functools
import json
import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from websockets.asyncio.server import ServerConnection, broadcast
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from gesturecast.bridges import ws_protocol
from gesturecast.bridges.control import WORDS_MESSAGE, decode_client_message, submit_control
from gesturecast.bridges.coords import coordinate_frame
from gesturecast.bridges.transport import ErrorThrottle
from gesturecast.bridges.viewer_http import AvatarServer, ViewerConnection, is_websocket_upgrade, static_response
from gesturecast.bridges.ws_access import AccessPolicy, send_refusal
from gesturecast.bridges.ws_listener import ThreadedListener
from gesturecast.controls import Control, ControlError, control_schema
from gesturecast.frames import VISEME_NAMES, PoseFrame
from gesturecast.message_rate import MessageRate, RateLimits
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

logger = logging.getLogger(__name__)

WS_DEFAULT_PORT = 8765
WS_PORT_FLAG = "--ws"  # the flag of `gesturecast live` that chooses this port
MAX_CLIENT_MESSAGE_BYTES = 64 * 1024
SLOW_CLIENT_BUFFER_BYTES = 256 * 1024
MAX_PENDING_FRAMES = 8
STOP_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class WebSocketConfig:
    host: str = "127.0.0.1"
    port: int = WS_DEFAULT_PORT
    token: str | None = None
    coordinate_frame: str = "internal"
    fps: float = 30.0
    style: str = ""  # the style in effect at start (the hello's ``style`` until the first frame)
    style_choices: tuple[str, ...] = ()
    body_parts: tuple[str, ...] = ()  # the model's body parts (part_styles controls); the hello lists them
    gestures: tuple[str, ...] = ()  # the lexicon's gestures (gesture controls); the hello lists them
    allow_origins: tuple[str, ...] = ()  # browser origins besides the viewer's own (ws_access)
    slow_client_buffer_bytes: int = SLOW_CLIENT_BUFFER_BYTES
    lipsync: bool = False  # frames carry viseme weights: the hello names them, frames append them (ws_protocol)
    viseme_names: tuple[str, ...] = VISEME_NAMES["vrm0"]  # their names in the hello when ``lipsync``
    face_names: tuple[str, ...] = ()  # frames carry these face weights (blinks, expressions) after the visemes
    avatar: Path | None = None  # the VRM file the viewer page shows (avatar_file.resolve_avatar); None: stick figure
    clock: Callable[[], float] = field(default=time.monotonic, compare=False)  # the engine's clock
    rate_limits: RateLimits = field(default_factory=RateLimits)  # per client: control and words messages


@dataclass
class ClientState:
    address: str
    rate: MessageRate  # its control and words messages
    wants_json: bool = False
    skipped_frames: int = 0


def _ignore_control(control: tuple[Control, ...]) -> None:
    logger.info("control message received but no engine is attached: %s", control)


class WebSocketBridge:
    """Start with :meth:`start`; :meth:`send` is thread-safe and never blocks on clients."""

    name = "websocket"

    def __init__(
        self,
        config: WebSocketConfig = WebSocketConfig(),
        on_control: Callable[[tuple[Control, ...]], dict | None] = _ignore_control,
        skeleton: Skeleton = CANONICAL_WITH_HANDS,
    ) -> None:
        self.access = AccessPolicy(config.host, config.token, config.allow_origins, config.clock)
        self.avatar = AvatarServer(config.avatar, self.access)  # /avatar.vrm, streamed (viewer_http)
        self.config = config
        self.on_control = on_control
        self.skeleton = skeleton
        self.coords = coordinate_frame(config.coordinate_frame)
        self.style = config.style
        self.gesture = ""  # the gesture the last broadcast frame named (side messages on change)
        self.dropped_pending = 0  # outbox: frames dropped (oldest first) before the event loop took them
        self.slow_client_skips = 0  # frames not sent to a client whose socket buffer was full (all clients)
        self._clients: dict[ServerConnection, ClientState] = {}
        self._pending: deque[PoseFrame] = deque(maxlen=MAX_PENDING_FRAMES)
        self._lock = threading.Lock()
        self._drain_scheduled = False
        self._listener = ThreadedListener(config.host, config.port, "gesturecast-websocket", STOP_TIMEOUT_S,
                                          port_flag=WS_PORT_FLAG)
        self._control_errors = ErrorThrottle("WebSocket control message rejected")

    # ---- lifecycle (caller's thread) ----
    def start(self) -> WebSocketBridge:
        self._listener.start(self._handle, process_request=self._process_request, max_size=MAX_CLIENT_MESSAGE_BYTES,
                             create_connection=functools.partial(ViewerConnection, self.avatar), open_timeout=None)
        logger.info("WebSocket stream and viewer on %s", self.url)
        return self

    @property
    def port(self) -> int:
        """The listening port (the bound one once started, also when ``config.port`` is 0)."""
        return self._listener.port

    @property
    def url(self) -> str:
        return f"http://{self.config.host}:{self.port}/"

    def close(self) -> None:
        if self._listener.loop.is_running():  # avatar downloads end now: a stalled one must not hold the close up
            self._listener.loop.call_soon_threadsafe(self.avatar.abort_all)
        self._listener.close()

    def client_count(self) -> int:
        return len(self._clients)

    def counters(self) -> dict[str, int]:
        """Frames this bridge did not deliver: outbox drop-oldest and slow-client skips (summed over clients)."""
        return {"outbox_drops": self.dropped_pending, "slow_client_skips": self.slow_client_skips}

    # ---- frames (engine thread) ----
    def send(self, frame: PoseFrame) -> None:
        with self._lock:
            if len(self._pending) == MAX_PENDING_FRAMES:
                self.dropped_pending += 1
            self._pending.append(frame)
            schedule = not self._drain_scheduled
            self._drain_scheduled = True
        if schedule:
            self._listener.loop.call_soon_threadsafe(self._drain)

    # ---- event-loop thread ----

    def _hello(self) -> str:
        return ws_protocol.hello_message(
            self.skeleton,
            self.coords,
            self.config.fps,
            self.style,
            self.config.style_choices,
            control_schema(),
            self.access.token_required,
            self.visemes,
            self.config.body_parts,
            self.config.gestures,
            self.config.face_names,
        )

    @property
    def _blend_counts(self) -> tuple[int, int]:
        """(V, E): how many viseme and face weights each frame carries."""
        return len(self.visemes), len(self.config.face_names)

    @property
    def visemes(self) -> tuple[str, ...]:
        """The viseme names of the hello: ``viseme_names`` with lip sync, else none."""
        return self.config.viseme_names if self.config.lipsync else ()

    def _process_request(self, connection: ServerConnection, request: Request) -> Response | None:
        """Upgrades pass the access policy (origin, wrong-token limit); plain GETs get the viewer files (the avatar
        is streamed by :class:`ViewerConnection` before this hook)."""
        if is_websocket_upgrade(request):
            return self.access.process_request(connection, request)
        return static_response(request.path, request.method)

    async def _handle(self, connection: ServerConnection) -> None:
        client = ClientState(str(connection.remote_address), MessageRate(self.config.clock, self.config.rate_limits))
        try:
            await connection.send(self._hello())
            self._clients[connection] = client
            async for message in connection:
                await self._answer(connection, client, message)
        except ConnectionClosed:
            logger.debug("client %s went away", client.address)
        finally:
            self._clients.pop(connection, None)

    async def _answer(self, connection: ServerConnection, client: ClientState, message: str | bytes) -> None:
        """Reply to one message; a refused one gets an ``error`` (and a wrong token also a close)."""
        try:
            reply = await self._apply(connection, client, message)
        except ControlError as error:
            self._control_errors.report(ControlError(f"from {client.address}: {error}"))
            await send_refusal(connection, error)
            return
        if reply is not None:
            await connection.send(reply)

    async def _apply(self, connection: ServerConnection, client: ClientState, message: str | bytes) -> str | None:
        if isinstance(message, bytes):
            raise ControlError("binary messages are not accepted; send JSON text")
        decoded = decode_client_message(message)
        kind = decoded["type"]
        if kind == "subscribe":
            return self._subscribe(client, decoded)
        if kind in ("control", WORDS_MESSAGE):  # a words message is a control holding only words
            self.access.verify_token(connection, decoded)
            return await self._control(client, {**decoded, "type": "control"})
        raise ControlError(f"unknown message type {kind!r}; use 'subscribe', 'control' or 'words'")

    def _subscribe(self, client: ClientState, message: dict) -> str:
        wire_format = message.get("format")
        if wire_format not in ("json", "binary"):
            raise ControlError("subscribe format must be 'json' or 'binary'")
        client.wants_json = wire_format == "json"
        return json.dumps({"type": "subscribed", "format": wire_format})

    async def _control(self, client: ClientState, message: dict) -> str:
        """Validate, check the client's rate, hand to the engine (which resolves the styles, off the event loop),
        then ack."""
        return await submit_control(message, self.on_control, client.rate)

    def _drain(self) -> None:
        with self._lock:
            frames = list(self._pending)
            self._pending.clear()
            self._drain_scheduled = False
        for frame in frames:
            self._broadcast(frame)

    def _broadcast(self, frame: PoseFrame) -> None:
        if frame.style != self.style:
            self.style = frame.style
            broadcast(self._clients, ws_protocol.style_message(frame.style))
        ready = self._ready_clients()
        send_unix = time.time()
        capture_unix = send_unix - (self.config.clock() - frame.capture_time)
        if frame.gesture != self.gesture:
            broadcast(self._clients, ws_protocol.gesture_message(self.gesture, frame.gesture, frame.seq,
                                                                 capture_unix))
            self.gesture = frame.gesture
        binary_clients = [c for c, state in ready if not state.wants_json]
        json_clients = [c for c, state in ready if state.wants_json]
        if binary_clients:
            broadcast(binary_clients, ws_protocol.binary_frame(frame, self.coords, capture_unix, send_unix,
                                                               *self._blend_counts))
        if json_clients:
            broadcast(json_clients, ws_protocol.json_frame(frame, self.coords, capture_unix, send_unix,
                                                           *self._blend_counts))

    def _ready_clients(self) -> Sequence[tuple[ServerConnection, ClientState]]:
        """Clients whose write buffer has room; the others skip this frame (never queued)."""
        ready = []
        for connection, state in self._clients.items():
            if connection.transport.get_write_buffer_size() > self.config.slow_client_buffer_bytes:
                state.skipped_frames += 1
                self.slow_client_skips += 1
                if state.skipped_frames == 1:
                    logger.warning("client %s is too slow; skipping frames for it", state.address)
            else:
                ready.append((connection, state))
        return ready
