"""Ray Serve's proxy closes a stream whose replica died with 1012 and a reason, not a bare 1006.

The relay that copies a stream's close code (:mod:`ray_replica`) lives in the replica, so it dies with it;
Ray's proxy then ends the client's WebSocket without a close frame (1006, "abnormal closure"). The proxy
is the one piece of code on the connection's path that outlives the replica. Ray loads proxy middlewares
from the import path in ``RAY_SERVE_HTTP_PROXY_CALLBACK_IMPORT_PATH`` (read by each proxy process when it
starts); :func:`proxy_middlewares` is that callback and :class:`ReplicaLossClose` the middleware: a
WebSocket that was accepted, not closed by the replica and not left by the client gets
``1012 replica lost; reconnect to start a new stream`` (RFC 6455 §7.4.1: "service restart"; Ray restarts
the replica and a reconnect is placed on a live one). Needs ``gesturecast[scale]``; docs/scale.md.
"""

from __future__ import annotations

import os

from starlette.middleware import Middleware
from starlette.types import ASGIApp, Message, Receive, Scope, Send

PROXY_CALLBACK_VARIABLE = "RAY_SERVE_HTTP_PROXY_CALLBACK_IMPORT_PATH"
PROXY_CALLBACK_PATH = "gesturecast.realtime.serve.ray_proxy:proxy_middlewares"
REPLICA_LOST_CODE = 1012  # service restart: the client may reconnect
REPLICA_LOST_REASON = "replica lost; reconnect to start a new stream"


class ReplicaLossClose:
    """Pure ASGI middleware: sends the close frame a dead replica could not send."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "websocket":
            await self.app(scope, receive, send)
            return
        seen: set[str] = set()  # ASGI message types that went by: accept, close, disconnect

        async def watched_receive() -> Message:
            message = await receive()
            seen.add(message["type"])
            return message

        async def watched_send(message: Message) -> None:
            seen.add(message["type"])
            await send(message)

        await self.app(scope, watched_receive, watched_send)
        if "websocket.accept" in seen and seen.isdisjoint({"websocket.close", "websocket.disconnect"}):
            await send({"type": "websocket.close", "code": REPLICA_LOST_CODE, "reason": REPLICA_LOST_REASON})


def proxy_middlewares() -> list[Middleware]:
    """The callback Ray's proxy calls (by :data:`PROXY_CALLBACK_PATH`) for its middlewares."""
    return [Middleware(ReplicaLossClose)]


def install_proxy_callback() -> None:
    """Set the variable in this process, before ``ray.init`` starts a local Ray: its proxy inherits it.
    A cluster joined with ``--ray-address`` needs it set where its nodes were started (docs/scale.md)."""
    os.environ[PROXY_CALLBACK_VARIABLE] = PROXY_CALLBACK_PATH
