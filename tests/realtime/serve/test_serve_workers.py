"""serve --workers: the parent deals each connection to the worker holding the fewest open ones."""

import json
from contextlib import ExitStack

from websockets.sync.client import connect

from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.serve.workers import Workers
from gesturecast.settings import Settings


def hello(connections: ExitStack, url: str, stream: str):
    """An open connection (closed with ``connections`` at the latest) that has received the server's hello, so a
    worker holds it."""
    connection = connections.enter_context(connect(f"{url}{stream}"))
    assert json.loads(connection.recv(timeout=30))["type"] == "hello"
    return connection


def test_connections_go_to_the_worker_holding_fewest_also_after_some_close(tiny_model, wait_until):
    workers = Workers(Settings(model=tiny_model[1], steps=2), ServeConfig(host="127.0.0.1", port=0), 2).start()
    url = f"ws://127.0.0.1:{workers.port}/stream/"
    try:
        with ExitStack() as connections:
            first, _, third = (hello(connections, url, name) for name in ("a", "b", "c"))  # to workers 0, 1, 0
            assert workers.dealer.dealt == [2, 1]
            first.close()
            third.close()  # worker 0 now holds none, worker 1 one
            assert wait_until(lambda: list(workers.dealer.counts) == [0, 1])
            hello(connections, url, "d")
            hello(connections, url, "e")  # both to worker 0: none, then as many as worker 1
            assert workers.dealer.dealt == [4, 1]
    finally:
        workers.stop()
