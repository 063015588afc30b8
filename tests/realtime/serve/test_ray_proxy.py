"""The proxy middleware adds a 1012 close frame only where a replica vanished after accepting a WebSocket.

The end-to-end check (a replica process killed in a real Ray cluster) is in ``test_serve_ray.py``; these
run the middleware around small real ASGI apps that end a WebSocket each way a relay can.
"""

import asyncio

import pytest

pytest.importorskip("starlette", reason="the proxy middleware is part of gesturecast[scale]")

from gesturecast.realtime.serve.ray_proxy import (  # noqa: E402
    PROXY_CALLBACK_PATH,
    REPLICA_LOST_CODE,
    REPLICA_LOST_REASON,
    ReplicaLossClose,
    proxy_middlewares,
)

ACCEPT = {"type": "websocket.accept"}
REPLICA_CLOSE = {"type": "websocket.close", "code": 1013, "reason": "server full (1 streams)"}
CLIENT_LEFT = {"type": "websocket.disconnect", "code": 1000}
LOST = {"type": "websocket.close", "code": REPLICA_LOST_CODE, "reason": REPLICA_LOST_REASON}


async def accept_then_vanish(scope, receive, send):
    """What Ray's proxy app does when the replica dies mid-stream: it returns without a close frame."""
    await send(ACCEPT)


async def accept_then_close(scope, receive, send):
    await send(ACCEPT)
    await send(REPLICA_CLOSE)


async def accept_until_client_leaves(scope, receive, send):
    await send(ACCEPT)
    while (await receive())["type"] != "websocket.disconnect":
        pass


async def plain_http(scope, receive, send):
    await send({"type": "http.response.start", "status": 200, "headers": []})


def sent_through(app, scope_type: str = "websocket", client: list[dict] | None = None) -> list[dict]:
    """Every message the wrapped app sent to the client."""
    sent, incoming = [], list(client or [])

    async def receive():
        return incoming.pop(0)

    async def send(message):
        sent.append(message)

    asyncio.run(ReplicaLossClose(app)({"type": scope_type}, receive, send))
    return sent


def test_a_vanished_replica_gets_1012_with_a_reason():
    assert sent_through(accept_then_vanish) == [ACCEPT, LOST]


def test_a_replica_close_passes_unchanged():
    assert sent_through(accept_then_close) == [ACCEPT, REPLICA_CLOSE]


def test_a_client_that_left_gets_no_close_frame():
    assert sent_through(accept_until_client_leaves, client=[{"type": "websocket.receive", "text": "{}"},
                                                            CLIENT_LEFT]) == [ACCEPT]


def test_http_passes_through():
    assert sent_through(plain_http, "http") == [{"type": "http.response.start", "status": 200, "headers": []}]


def test_the_callback_path_names_the_callback():
    module, name = PROXY_CALLBACK_PATH.split(":")
    assert module == ReplicaLossClose.__module__ and name == proxy_middlewares.__name__
    assert [middleware.cls for middleware in proxy_middlewares()] == [ReplicaLossClose]
