"""One Ray Serve replica of ``gesturecast serve --ray``: today's :class:`GestureServer` plus a WebSocket relay.

Ray Serve's HTTP proxy hands each client WebSocket to one replica for the connection's whole life (one
WebSocket = one ongoing request), so a stream and its KV cache stay on that replica. Inside the replica,
:class:`StreamRelay` opens the same path on the replica's own ``GestureServer`` (loopback, any free port)
and copies messages both ways, close code and reason included: the client speaks today's protocol (hello,
start, audio, control, end, stats) and sees today's refusals (1013 when the replica is full, 1008, 1009).
Placement: :mod:`ray_router`. Needs ``gesturecast[scale]`` (Ray, FastAPI); docs/scale.md.
"""

import asyncio
import logging
from dataclasses import replace

from fastapi import FastAPI, WebSocket
from ray import serve
from ray.serve import Application
from starlette.websockets import WebSocketDisconnect, WebSocketState
from websockets.asyncio.client import ClientConnection, connect
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.frames import CloseCode

from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

LOOPBACK = "127.0.0.1"
FORWARDED_HEADERS = ("origin",)  # the replica's server checks browser origins as plain serve does
DISCONNECT = "websocket.disconnect"

api = FastAPI(docs_url=None, redoc_url=None, openapi_url=None)  # WebSockets only


class StreamRelay:
    """The replica's ``GestureServer`` on loopback and the copying of one client's messages to and from it."""

    def __init__(self, settings: Settings, config: ServeConfig) -> None:
        self.server = start_server(settings, replace(config, host=LOOPBACK, port=0), MonotonicClock())
        self.base = f"ws://{LOOPBACK}:{self.server.port}"

    async def relay(self, client: WebSocket, path: str) -> None:
        """Serve one client: its stream lives on this replica's server until either side closes."""
        headers = {name: client.headers[name] for name in FORWARDED_HEADERS if name in client.headers}
        try:
            upstream = await connect(f"{self.base}/{path}", additional_headers=headers, max_size=None)
        except InvalidStatus as refusal:  # a refused origin or address: HTTP 403 before the handshake
            logger.info("relay: %s refused (%s)", path, refusal.response.status_code)
            await client.close()
            return
        async with upstream:
            await client.accept()
            to_server = asyncio.create_task(self._client_to_server(client, upstream))
            try:
                await self._server_to_client(upstream, client)
            finally:
                to_server.cancel()

    @staticmethod
    async def _client_to_server(client: WebSocket, upstream: ClientConnection) -> None:
        """Copy audio and JSON to the server; a client that leaves closes the stream (the server frees it)."""
        while True:
            message = await client.receive()
            if message["type"] == DISCONNECT:  # its code may be 1006, which no one may send: close plainly
                await upstream.close()
                return
            data = message.get("bytes")
            try:
                await upstream.send(data if data is not None else message["text"])
            except ConnectionClosed:
                return

    @staticmethod
    async def _server_to_client(upstream: ClientConnection, client: WebSocket) -> None:
        """Copy hello, poses, acks and stats to the client, then close it with the server's code and reason."""
        try:
            async for message in upstream:
                if isinstance(message, bytes):
                    await client.send_bytes(message)
                else:
                    await client.send_text(message)
        except ConnectionClosed:
            pass  # the code and reason are read below
        except (WebSocketDisconnect, RuntimeError):
            return  # the client is gone: _client_to_server closes the server's side
        if client.application_state != WebSocketState.DISCONNECTED:
            code = upstream.close_code or CloseCode.INTERNAL_ERROR
            await client.close(code, upstream.close_reason or "")

    def close(self) -> None:
        self.server.close()


@serve.deployment(name="GestureReplica")
@serve.ingress(api)
class GestureReplica:
    """A Ray Serve replica: every WebSocket path goes to the replica's own ``gesturecast serve``."""

    def __init__(self, settings: Settings, config: ServeConfig) -> None:
        self.relay = StreamRelay(settings, config)

    @api.websocket("/{path:path}")
    async def stream(self, websocket: WebSocket, path: str) -> None:
        await self.relay.relay(websocket, path)

    def __del__(self) -> None:
        """Ray calls this once the replica has drained (or is being torn down)."""
        self.relay.close()


def replica_application(settings: Settings, config: ServeConfig, options: dict) -> Application:
    """The Ray Serve application: ``options`` are the deployment's (replicas, autoscaling, drain, router)."""
    return GestureReplica.options(**options).bind(settings, config)
