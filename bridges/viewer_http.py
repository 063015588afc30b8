"""Plain HTTP on the WebSocket port: serves the browser viewer page (bridges/viewer/) and its avatar.

The viewer's own files are small and packaged: :func:`static_response` answers them whole from the handshake
hook. ``/avatar.vrm`` (the file chosen by :func:`gesturecast.bridges.avatar_file.resolve_avatar`, often tens of MB)
is streamed from disk by :class:`AvatarServer` through :class:`ViewerConnection`: chunks read off the event loop,
each sent once the client has taken the previous ones, at most :data:`MAX_AVATAR_TRANSFERS` transfers at once
(more get 503), and behind the port's access rules (:mod:`ws_access`): browser origin, the wrong-token limit, and
the token whenever the port needs one (``Authorization: Bearer TOKEN``, as the viewer page sends the token of its
own URL, or ``?token=TOKEN``). ``HEAD`` gets the headers and no body; other methods get 405.
"""

from __future__ import annotations

import asyncio
import logging
import os
from http import HTTPStatus
from importlib import resources
from pathlib import Path
from typing import BinaryIO
from urllib.parse import parse_qs, urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

from gesturecast.bridges.ws_access import AccessPolicy, client_address, client_key, tokens_match

logger = logging.getLogger(__name__)

JAVASCRIPT = "text/javascript; charset=utf-8"
TEXT = "text/plain; charset=utf-8"
VIEWER_FILES: dict[str, tuple[str, str]] = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/viewer.js": ("viewer.js", JAVASCRIPT),
    "/stick.js": ("stick.js", JAVASCRIPT),
    "/avatar.js": ("avatar.js", JAVASCRIPT),
    "/mouth.js": ("mouth.js", JAVASCRIPT),
    "/face.js": ("face.js", JAVASCRIPT),
    "/viewer.css": ("viewer.css", "text/css; charset=utf-8"),
    "/vendor/three-vrm.bundle.js": ("vendor/three-vrm.bundle.js", JAVASCRIPT),
    "/vendor/three.LICENSE": ("vendor/three.LICENSE", TEXT),
    "/vendor/three-vrm.LICENSE": ("vendor/three-vrm.LICENSE", TEXT),
    "/vendor/three-vrm-animation.LICENSE": ("vendor/three-vrm-animation.LICENSE", TEXT),
}
AVATAR_PATH = "/avatar.vrm"
AVATAR_TYPE = "model/gltf-binary"
READ_METHODS = ("GET", "HEAD")
MAX_AVATAR_TRANSFERS = 4  # avatar downloads at once; each holds at most one chunk plus the socket's write buffer
AVATAR_CHUNK_BYTES = 64 * 1024
STALL_TIMEOUT_S = 10.0  # a client that takes no avatar data for this long is dropped
OPEN_TIMEOUT_S = 10.0  # for the request line and headers, and for a WebSocket handshake (websockets' default)
RETRY_AFTER_S = 1


def is_websocket_upgrade(request: Request) -> bool:
    return "websocket" in request.headers.get("Upgrade", "").lower()


def route(path: str) -> str:
    """The path without its query string."""
    return path.split("?", 1)[0]


def viewer_file(name: str) -> bytes:
    return (resources.files("gesturecast.bridges") / "viewer").joinpath(*name.split("/")).read_bytes()


def plain_response(status: HTTPStatus, body: bytes, content_type: str, method: str = "GET",
                   extra: tuple[tuple[str, str], ...] = ()) -> Response:
    """A complete response; for ``HEAD`` the same headers (its Content-Length too) and no body."""
    headers = Headers([("Content-Type", content_type), ("Content-Length", str(len(body))),
                       ("Cache-Control", "no-store"), ("Connection", "close"), *extra])
    return Response(status.value, status.phrase, headers, b"" if method == "HEAD" else body)


def static_response(path: str, method: str = "GET") -> Response:
    """200 with the viewer file for ``path`` (query string ignored), else 404; 405 for a method other than GET and
    HEAD. (``/avatar.vrm`` is streamed by :class:`AvatarServer`, not answered here.)"""
    if method not in READ_METHODS:
        return plain_response(HTTPStatus.METHOD_NOT_ALLOWED, b"only GET and HEAD\n", TEXT, method,
                              (("Allow", ", ".join(READ_METHODS)),))
    entry = VIEWER_FILES.get(route(path))
    if entry is None:
        return plain_response(HTTPStatus.NOT_FOUND, b"not found\n", TEXT, method)
    return plain_response(HTTPStatus.OK, viewer_file(entry[0]), entry[1], method)


def request_token(request: Request) -> str | None:
    """The token of a plain HTTP request: ``Authorization: Bearer TOKEN``, else ``?token=TOKEN``, else None."""
    scheme, _, value = request.headers.get("Authorization", "").partition(" ")
    if scheme.lower() == "bearer" and value.strip():
        return value.strip()
    tokens = parse_qs(urlsplit(request.path).query).get("token")
    return tokens[0] if tokens else None


class AvatarServer:
    """Streams the avatar file to plain HTTP requests of :data:`AVATAR_PATH` (event-loop thread)."""

    def __init__(self, avatar: Path | None, access: AccessPolicy, max_transfers: int = MAX_AVATAR_TRANSFERS,
                 chunk_bytes: int = AVATAR_CHUNK_BYTES, stall_timeout_s: float = STALL_TIMEOUT_S) -> None:
        self.avatar = avatar
        self.access = access
        self.max_transfers = max_transfers
        self.chunk_bytes = chunk_bytes
        self.stall_timeout_s = stall_timeout_s
        self.transfers: set[ServerConnection] = set()  # connections receiving the file now

    @staticmethod
    def handles(request: Request) -> bool:
        return route(request.path) == AVATAR_PATH and not is_websocket_upgrade(request)

    def abort_all(self) -> None:
        """Drop every transfer (the server is closing; a stalled client must not hold the shutdown up)."""
        for connection in list(self.transfers):
            connection.transport.abort()

    async def respond(self, connection: ServerConnection, request: Request) -> None:
        """Answer one request (a refusal, the headers for HEAD, or the whole file), then close the connection."""
        try:
            refused = self._refusal(connection, request)
            if refused is not None:
                connection.transport.write(refused.serialize())
            else:
                await self._send_file(connection, request.method)
            await self._closed(connection)
        except (asyncio.TimeoutError, OSError) as error:  # a stalled or vanished client, an unreadable file
            logger.debug("avatar transfer to %s ended: %r", client_address(connection), error)
            connection.transport.abort()

    def _refusal(self, connection: ServerConnection, request: Request) -> Response | None:
        """The response refusing this request, or None when the file may be sent."""
        method = request.method
        if method not in READ_METHODS:
            return static_response(request.path, method)
        denied = self.access.process_request(connection, request)  # browser origin, wrong-token limit
        if denied is not None:
            return head_only(denied) if method == "HEAD" else denied
        if self.access.token_required:
            token = request_token(request)
            if token is None:
                return plain_response(HTTPStatus.UNAUTHORIZED, b"this server needs a token: send "
                                      b"Authorization: Bearer TOKEN (or ?token=TOKEN)\n", TEXT, method)
            if not tokens_match(token, self.access.token or ""):
                self.access.failures.record(client_key(connection, request.headers))
                return plain_response(HTTPStatus.FORBIDDEN, b"wrong token\n", TEXT, method)
        if self.avatar is None or not self.avatar.is_file():
            return plain_response(HTTPStatus.NOT_FOUND, b"no avatar on this server\n", TEXT, method)
        if len(self.transfers) >= self.max_transfers:
            return plain_response(HTTPStatus.SERVICE_UNAVAILABLE, b"too many avatar downloads; retry\n", TEXT,
                                  method, (("Retry-After", str(RETRY_AFTER_S)),))
        return None

    async def _send_file(self, connection: ServerConnection, method: str) -> None:
        handle = await asyncio.to_thread(self.avatar.open, "rb")
        self.transfers.add(connection)
        try:
            size = os.fstat(handle.fileno()).st_size
            headers = Headers([("Content-Type", AVATAR_TYPE), ("Content-Length", str(size)),
                               ("Cache-Control", "no-store"), ("Connection", "close")])
            connection.transport.write(Response(HTTPStatus.OK.value, HTTPStatus.OK.phrase, headers).serialize())
            if method == "GET":
                await self._send_chunks(connection, handle, size)
        finally:
            self.transfers.discard(connection)
            await asyncio.to_thread(handle.close)

    async def _send_chunks(self, connection: ServerConnection, handle: BinaryIO, size: int) -> None:
        """``size`` bytes of ``handle``, one chunk at a time, each written once the client took the last ones."""
        remaining = size
        while remaining > 0 and not connection.transport.is_closing():
            chunk = await asyncio.to_thread(handle.read, min(self.chunk_bytes, remaining))
            if not chunk:  # the file shrank: the client sees a short body and the close
                break
            connection.transport.write(chunk)
            remaining -= len(chunk)
            await asyncio.wait_for(connection.drain(), self.stall_timeout_s)

    async def _closed(self, connection: ServerConnection) -> None:
        """Close once everything written has gone out (bounded by the stall timeout)."""
        connection.transport.close()
        await asyncio.wait_for(asyncio.shield(connection.connection_lost_waiter), self.stall_timeout_s)


def head_only(response: Response) -> Response:
    """``response`` without its body (the answer to HEAD)."""
    return Response(response.status_code, response.reason_phrase, response.headers, b"")


class ViewerConnection(ServerConnection):
    """A connection on the viewer port. A request for the avatar is answered here, by :class:`AvatarServer`:
    websockets sends a handshake response in one write and within its opening timeout, which would hold a whole
    large file in memory per request and cut a slow download short. Everything else is the usual handshake
    (``process_request`` serves the viewer files), under the same :data:`OPEN_TIMEOUT_S` (give the listener
    ``open_timeout=None``)."""

    def __init__(self, avatar_server: AvatarServer, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.avatar_server = avatar_server

    async def handshake(self, *args, **kwargs) -> None:
        done, _ = await asyncio.wait([self.request_rcvd, self.connection_lost_waiter], timeout=OPEN_TIMEOUT_S,
                                     return_when=asyncio.FIRST_COMPLETED)
        if not done:
            raise asyncio.TimeoutError("no HTTP request within the opening timeout")  # websockets aborts it
        if self.request is not None and self.avatar_server.handles(self.request):
            await self.avatar_server.respond(self, self.request)
            return
        await asyncio.wait_for(super().handshake(*args, **kwargs), OPEN_TIMEOUT_S)
