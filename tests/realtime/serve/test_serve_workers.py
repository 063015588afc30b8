"""serve --workers: the parent deals each connection to the ready worker holding the fewest open ones; a worker that
dies is never dealt to and is started again; every process ends on every signal (real processes)."""

import json
import multiprocessing
import os
import re
import signal
import socket
from collections import Counter
from contextlib import ExitStack
from pathlib import Path

from websockets.sync.client import connect

from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.serve.workers import Workers
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

START_BOUND_S = 120.0  # two workers load the model on a loaded 2-core machine
STOP_BOUND_S = 10.0  # SIGTERM ends every process of the service within 10 s (docs/serve.md)


def hello(connections: ExitStack, url: str, stream: str):
    """An open connection (closed with ``connections`` at the latest) that has received the server's hello, so a
    worker holds it."""
    connection = connections.enter_context(connect(f"{url}{stream}", open_timeout=30))
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
            assert wait_until(lambda: [slot.open for slot in workers.slots] == [0, 1])
            hello(connections, url, "d")
            hello(connections, url, "e")  # both to worker 0: none, then as many as worker 1
            assert workers.dealer.dealt == [4, 1]
    finally:
        workers.stop()


def test_a_connection_made_while_no_worker_is_ready_waits_for_the_replacement(tiny_model, wait_until):
    workers = Workers(Settings(model=tiny_model[1], steps=2), ServeConfig(host="127.0.0.1", port=0), 1).start()
    try:
        os.kill(workers.processes[0].pid, signal.SIGKILL)
        assert wait_until(lambda: not workers.slots[0].ready)  # seen dead: no worker is ready now
        with ExitStack() as connections:
            hello(connections, f"ws://127.0.0.1:{workers.port}/stream/", "waits")  # served by the replacement
        assert workers.respawns == 1 and workers.dealer.unserved == 0
    finally:
        workers.stop()


def started_workers(server, count: int) -> tuple[str, list[int]]:
    """The stream URL and the worker pids of a ``serve --workers`` process once ``count`` workers are ready (the
    parent has their reports: a worker that ends before that stops the run)."""
    url = re.search(r"ws://\S+/stream/", server.wait_for_stderr("serving streams on", START_BOUND_S)).group(0)
    server.wait_for_stderr(" ready (pid ", START_BOUND_S, count=count)
    workers = [pid for pid in server.children() if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes()]
    return url, sorted(workers)


def test_a_killed_worker_is_never_dealt_to_is_started_again_and_sigterm_ends_every_process(tiny_model, cli_process):
    server = cli_process(["serve", "--workers", "2", "--port", "0", "--model", str(tiny_model[1])])
    url, pids = started_workers(server, 2)
    os.kill(pids[0], signal.SIGKILL)  # as the OOM killer would
    with ExitStack() as connections:  # at once: one passed while it dies is dealt again, none is lost
        for name in ("while-one-is-dead-a", "while-one-is-dead-b", "while-one-is-dead-c"):
            hello(connections, url, name)
    server.wait_for_stderr(f"(pid {pids[0]}) ended (killed by SIGKILL)", START_BOUND_S)
    server.wait_for_stderr(" ready (pid ", START_BOUND_S, count=3)  # the dead worker's replacement
    with ExitStack() as connections:
        for name in ("after-a", "after-b", "after-c"):
            hello(connections, url, name)
    children = server.children()  # the workers and multiprocessing's resource tracker
    code, seconds, stdout = server.stop(signal.SIGTERM, STOP_BOUND_S)
    assert code == 143 and "stopped by SIGTERM" in stdout, (code, stdout, server.stderr_lines)
    assert server.still_running(children, STOP_BOUND_S) == []
    assert not any("could not pass a connection" in line for line in server.stderr_lines)


def test_a_killed_parent_takes_every_worker_with_it(tiny_model, cli_process):
    server = cli_process(["serve", "--workers", "2", "--port", "0", "--model", str(tiny_model[1])])
    started_workers(server, 2)
    children = server.children()
    assert len(children) >= 2
    server.process.kill()
    server.process.wait()
    assert server.still_running(children, STOP_BOUND_S) == []


def test_a_workers_private_socket_cannot_be_reached_and_a_unix_peer_is_served(tiny_model, caplog):
    config = ServeConfig(host="127.0.0.1", port=0, token="a-strong-token-0123456789", dealt=True)
    with caplog.at_level("INFO"):
        server = start_server(Settings(model=tiny_model[1], steps=2), config, MonotonicClock())
    try:
        (private,) = server._listener._server.sockets
        name = private.getsockname()
        assert name.startswith("/") and not os.path.exists(name)  # no name anyone could connect to
        assert not any("listening on" in record.getMessage() for record in caplog.records)
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)  # a peer with no IP address
        server.adopt(theirs)
        with connect("ws://localhost/stream/unix", sock=ours, open_timeout=30) as connection:
            assert json.loads(connection.recv(timeout=30))["type"] == "hello"
    finally:
        server.close()


def fake_worker(channel: socket.socket, ends_after_ready: bool, wait_for) -> None:
    """A worker process without a model: waits for ``wait_for`` (an event, or None), reports ready, then ends at
    once (``ends_after_ready``: as if killed) or serves until the parent shuts the channel."""
    if wait_for is not None:
        wait_for.wait()
    channel.sendall(json.dumps(["ready", os.getpid()]).encode() + b"\n")
    if not ends_after_ready:
        channel.recv(1)


def test_a_worker_killed_after_it_was_ready_is_started_again_while_the_others_start(monkeypatch):
    """worker-0 ready, then killed while worker-1 still loads: that ended the whole server ("worker-0 ended before it
    was ready"); only a worker that never came up may. worker-1 waits for worker-0's replacement, so the order holds."""
    context = multiprocessing.get_context("fork")
    replaced = context.Event()
    lives: Counter[int] = Counter()

    def spawn(self, index: int):
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        life = lives[index]
        lives[index] += 1
        if (index, life) == (0, 1):
            replaced.set()
        process = context.Process(target=fake_worker, args=(theirs, (index, life) == (0, 0),
                                                             replaced if index == 1 else None))
        process.start()
        theirs.close()
        return process, ours

    monkeypatch.setattr(Workers, "_spawn", spawn)
    workers = Workers(Settings(), ServeConfig(host="127.0.0.1", port=0), 2).start()
    try:
        assert all(slot.ready for slot in workers.slots) and workers.respawns == 1 and lives == {0: 2, 1: 1}
    finally:
        workers.stop()
