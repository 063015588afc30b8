"""``serve --workers N``: N server processes on one port, so that streams use every core.

One server process runs every stream's Python work (features, pose building, the sampler loop, the protocol)
under one interpreter lock: it gets about one core for it whatever the machine has (docs/serve.md). With
``--workers N`` the command starts N processes, each a whole ``serve`` server (its own model, batched denoiser
and ``--max-streams`` slots) listening on the same port with ``SO_REUSEPORT``; the kernel deals each new
connection to one of them. The parent process loads no model: it reserves the port, starts the workers, waits
for each to listen (a worker that fails names its error and stops the others), prints where streams go, and on
Ctrl-C, SIGTERM or SIGHUP asks every worker to close its streams as ``serve`` does, then prints one line over all.
Linux only (``SO_REUSEPORT`` balances connections there).
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import queue
import signal
import socket
import time
from contextlib import closing
from dataclasses import replace

from gesturecast import stop_signals
from gesturecast.errors import UserError
from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

READY_TIMEOUT_S = 300.0  # a worker loads the model and builds a probe session before it listens
STOP_TIMEOUT_S = 20.0
PARENT_CHECK_S = 0.5  # a worker whose parent is gone (killed) stops within this long
MAX_WORKERS = 64


def reserve_port(host: str, port: int) -> socket.socket:
    """A bound, not listening socket on ``host:port`` (0: a free port) with SO_REUSEPORT set: the workers' sockets
    join it; it holds the port until they listen (the kernel gives connections only to listening sockets)."""
    if not hasattr(socket, "SO_REUSEPORT"):
        raise UserError("serve --workers needs SO_REUSEPORT (Linux); run one server per port instead")
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    holder = socket.socket(family, socket.SOCK_STREAM)
    holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    try:
        holder.bind((host, port))
    except OSError as error:
        holder.close()
        raise UserError(f"cannot listen on {host}:{port}: {error.strerror}; pick another with --port") from None
    return holder


def run_worker(settings: Settings, config: ServeConfig, reports: multiprocessing.Queue,
               stop: multiprocessing.Event, log_level: int) -> None:
    """One worker process: a ``serve`` server on the shared port until the parent sets ``stop`` (or is gone);
    reports "ready" (or the error that stopped it), then its closed streams. Ctrl-C, SIGTERM and SIGHUP are the
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
        self._holder = reserve_port(config.host, config.port)
        self.port = self._holder.getsockname()[1]
        shared = replace(config, port=self.port, reuse_port=True)
        level = logging.getLogger().getEffectiveLevel()
        self.processes = [context.Process(target=run_worker, args=(settings, shared, self.reports, self.stop_event,
                                                                   level),
                                          name=f"worker-{i}") for i in range(count)]
        self.listening = 0  # workers that reported "ready": each reports its streams when it stops

    def start(self) -> Workers:
        """Start every worker and wait until each listens; a failure stops the others and raises its error."""
        with closing(self._holder):
            for process in self.processes:
                process.start()
            for _ in self.processes:
                kind, detail = self.reports.get(timeout=READY_TIMEOUT_S)
                if kind == "error":
                    self.stop()
                    raise UserError(detail)
                self.listening += 1
        return self

    def stop(self) -> list[dict]:
        """Ask each worker to close its streams; returns the closed streams' stats of all."""
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
