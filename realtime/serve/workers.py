"""``serve --workers N``: N server processes on one port, so that streams use every core.

One server process runs every stream's Python work (features, pose building, the sampler loop, the protocol)
under one interpreter lock: it gets about one core for it whatever the machine has (docs/serve.md). With
``--workers N`` the command starts N processes, each a whole ``serve`` server (its own model, batched denoiser
and ``--max-streams`` slots) without a port of its own. The parent process loads no model: it listens on the port,
starts the workers, waits for each to be ready (a worker that fails names its error and stops the others), then
deals each connection to the worker holding the fewest (:mod:`.dealer`), prints where streams go, and on Ctrl-C,
SIGTERM or SIGHUP stops dealing and asks every worker to close its streams as ``serve`` does, then prints one line
over all. Linux only (sockets are passed between processes with ``SCM_RIGHTS``).
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import queue
import signal
import socket
import sys
import time
from dataclasses import replace
from multiprocessing.sharedctypes import SynchronizedArray

from gesturecast import stop_signals
from gesturecast.errors import UserError
from gesturecast.realtime.serve.dealer import ConnectionDealer, receive_connections
from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

READY_TIMEOUT_S = 300.0  # a worker loads the model and builds a probe session before it listens
STOP_TIMEOUT_S = 20.0
PARENT_CHECK_S = 0.5  # a worker whose parent is gone (killed) stops within this long
MAX_WORKERS = 64


def listen_port(host: str, port: int) -> socket.socket:
    """The listening socket on ``host:port`` (0: a free port) whose connections the parent deals out."""
    if not sys.platform.startswith("linux"):  # macOS has send_fds, but not the abstract socket names used here
        raise UserError(f"serve --workers runs on Linux only (this is {sys.platform}); "
                        "run one `gesturecast serve` per port instead")
    try:
        return socket.create_server((host, port), family=socket.AF_INET6 if ":" in host else socket.AF_INET)
    except OSError as error:
        raise UserError(f"cannot listen on {host}:{port}: {error.strerror}; pick another with --port") from None


def run_worker(settings: Settings, config: ServeConfig, reports: multiprocessing.Queue,
               stop: multiprocessing.Event, log_level: int, channel: socket.socket, counts: SynchronizedArray,
               index: int) -> None:
    """One worker process: a ``serve`` server fed the connections the parent passes on ``channel`` until the parent
    sets ``stop`` (or is gone); reports "ready" (or the error that stopped it), then its closed streams. Ctrl-C,
    SIGTERM and SIGHUP are the
    parent's to handle: a terminal or systemd sends them to every process of the service, and a second signal in
    the middle of a close must not cut it short."""
    for signum in (signal.SIGINT, *stop_signals.STOP_SIGNALS):
        signal.signal(signum, signal.SIG_IGN)
    logging.basicConfig(level=log_level, format=f"%(levelname)s {multiprocessing.current_process().name} "
                                                "%(name)s: %(message)s")
    parent = os.getppid()
    try:
        server = start_server(settings, config, MonotonicClock())
    except UserError as error:
        reports.put(("error", str(error)))
        return
    receive_connections(channel, server, counts, index)
    reports.put(("ready", os.getpid()))
    try:
        while not stop.wait(PARENT_CHECK_S) and os.getppid() == parent:
            pass
    finally:
        server.close()
    reports.put(("served", list(server.finished)))


class Workers:
    """The worker processes of one ``serve --workers N`` run (start, wait until they listen, stop)."""

    def __init__(self, settings: Settings, config: ServeConfig, count: int) -> None:
        if not 1 <= count <= MAX_WORKERS:
            raise UserError(f"--workers must be within 1..{MAX_WORKERS}, got {count}")
        context = multiprocessing.get_context("spawn")
        self.reports = context.Queue()
        self.stop_event = context.Event()
        listener = listen_port(config.host, config.port)
        self.port = listener.getsockname()[1]
        shared = replace(config, port=self.port, dealt=True)
        level = logging.getLogger().getEffectiveLevel()
        counts = context.Array("i", count)  # open connections per worker
        pairs = [socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM) for _ in range(count)]
        self.processes = [context.Process(target=run_worker, args=(settings, shared, self.reports, self.stop_event,
                                                                   level, pairs[i][1], counts, i),
                                          name=f"worker-{i}") for i in range(count)]
        self.dealer = ConnectionDealer(listener, [ours for ours, _ in pairs], counts)
        self._their_ends = [theirs for _, theirs in pairs]
        self.listening = 0  # workers that reported "ready": each reports its streams when it stops

    def start(self) -> Workers:
        """Start every worker, wait until each is ready, then deal connections; a failure stops the others and
        raises its error."""
        for process in self.processes:
            process.start()
        for theirs in self._their_ends:  # each worker holds its own copy now
            theirs.close()
        for _ in self.processes:
            kind, detail = self.reports.get(timeout=READY_TIMEOUT_S)
            if kind == "error":
                self.stop()
                raise UserError(detail)
            self.listening += 1
        self.dealer.start()
        return self

    def stop(self) -> list[dict]:
        """Stop dealing, ask each worker to close its streams; returns the closed streams' stats of all."""
        self.dealer.close()
        self.stop_event.set()
        deadline = time.monotonic() + STOP_TIMEOUT_S
        served, reports = [], 0
        while reports < self.listening:  # read before joining: a worker exits once its report is in the pipe
            try:
                kind, detail = self.reports.get(timeout=max(deadline - time.monotonic(), 0.0))
            except queue.Empty:
                break
            if kind == "served":
                served, reports = served + detail, reports + 1
        for process in self.processes:
            process.join(max(deadline - time.monotonic(), 0.0))
            if process.is_alive():
                process.terminate()
                process.join()
        return served
