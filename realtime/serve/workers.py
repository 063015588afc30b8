"""``serve --workers N``: N server processes on one port, so that streams use every core.

One server process runs every stream's Python work (features, pose building, the sampler loop, the protocol)
under one interpreter lock: it gets about one core for it whatever the machine has (docs/serve.md). With
``--workers N`` the command starts N processes, each a whole ``serve`` server (its own model, batched denoiser
and ``--max-streams`` slots) without a port of its own. The parent process loads no model: it listens on the port,
starts the workers, waits for each to be ready (a worker that fails before it was ever ready names its error and
stops the others; one that ends after it was ready is started again), then deals each connection to the ready worker
holding the fewest (:mod:`.dealer`) and prints where streams go.

A worker that dies while serving (the OOM killer, a crash) loses its streams, and no connection goes to it; it is
started again after a back-off (1 s, doubling while workers keep dying within :data:`STEADY_S` of being ready, at
most :data:`RESPAWN_MAX_S`), each step logged. On Ctrl-C, SIGTERM or SIGHUP the parent stops dealing and tells every
worker to close its streams as ``serve`` does, prints one line over all, and kills any worker still running after
:data:`STOP_TIMEOUT_S`. A worker whose parent is gone (killed) sees its socket pair end and stops. Linux only
(sockets are passed between processes with ``SCM_RIGHTS``).
"""

from __future__ import annotations

import logging
import multiprocessing
import multiprocessing.connection
import os
import signal
import socket
import sys
import threading
import time
from contextlib import suppress
from dataclasses import replace

from gesturecast import stop_signals
from gesturecast.errors import UserError
from gesturecast.realtime.serve.dealer import ConnectionDealer, WorkerLink, WorkerSlot
from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.serve.shared_failures import shared_failures_file
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

READY_TIMEOUT_S = 300.0  # a worker loads the model and builds a probe session before it listens
STOP_TIMEOUT_S = 8.0  # the workers close their streams within this; then they are killed (all ends within 10 s)
KILL_TIMEOUT_S = 1.0
PARENT_CHECK_S = 0.5  # a worker also stops within this once its parent has gone
MAX_WORKERS = 64
RESPAWN_FIRST_S = 1.0  # a dead worker's replacement starts this long after it died, doubling while they keep dying
RESPAWN_MAX_S = 30.0
STEADY_S = 10.0  # a worker ready this long before it died is restarted after RESPAWN_FIRST_S again
WATCH_S = 0.25  # the supervisor's longest sleep (respawns and the stop are looked at this often)
READ_BYTES = 1 << 16


def listen_port(host: str, port: int) -> socket.socket:
    """The listening socket on ``host:port`` (0: a free port) whose connections the parent deals out."""
    if not sys.platform.startswith("linux"):  # the worker supervision and socket passing are tested on Linux only
        raise UserError(f"serve --workers runs on Linux only (this is {sys.platform}); "
                        "run one `gesturecast serve` per port instead")
    try:
        return socket.create_server((host, port), family=socket.AF_INET6 if ":" in host else socket.AF_INET)
    except OSError as error:
        raise UserError(f"cannot listen on {host}:{port}: {error.strerror}; pick another with --port") from None


def run_worker(settings: Settings, config: ServeConfig, log_level: int, channel: socket.socket) -> None:
    """One worker process: a ``serve`` server fed the connections the parent passes on ``channel`` until the parent
    shuts the channel (or is gone); reports "ready" (or the error that stopped it), each closed connection, then
    its closed streams (:class:`WorkerLink`). Ctrl-C, SIGTERM and SIGHUP are the parent's to handle: a terminal or
    systemd sends them to every process of the service, and a second signal in the middle of a close must not cut
    it short."""
    for signum in (signal.SIGINT, *stop_signals.STOP_SIGNALS):
        signal.signal(signum, signal.SIG_IGN)
    logging.basicConfig(level=log_level, format=f"%(levelname)s {multiprocessing.current_process().name} "
                                                "%(name)s: %(message)s")
    link = WorkerLink(channel)
    parent = os.getppid()
    try:
        server = start_server(settings, config, MonotonicClock())
    except UserError as error:
        link.report("error", str(error))
        return
    link.receive_connections(server)
    link.report("ready", os.getpid())
    try:
        while not link.stopped.wait(PARENT_CHECK_S) and os.getppid() == parent:
            pass
    finally:
        server.close()
    link.report("served", list(server.finished))


def how_it_ended(exitcode: int | None) -> str:
    """A process's end in words: ``killed by SIGKILL``, ``exit status 1``."""
    if exitcode is not None and exitcode < 0:
        return f"killed by {signal.Signals(-exitcode).name}"
    return f"exit status {exitcode}"


class Workers:
    """The worker processes of one ``serve --workers N`` run: start them, deal to them, restart the dead, stop."""

    def __init__(self, settings: Settings, config: ServeConfig, count: int) -> None:
        if not 1 <= count <= MAX_WORKERS:
            raise UserError(f"--workers must be within 1..{MAX_WORKERS}, got {count}")
        self._context = multiprocessing.get_context("spawn")
        self._listener = listen_port(config.host, config.port)
        self.port = self._listener.getsockname()[1]
        self.token_failures = shared_failures_file()  # the wrong-token limit counts across the workers
        self._worker_args = (settings, replace(config, port=self.port, dealt=True, token_failures=self.token_failures),
                             logging.getLogger().getEffectiveLevel())
        self.count = count
        self.lock = threading.Condition()  # the slots' state: the dealer reads it, the supervisor changes it
        self.slots: list[WorkerSlot] = []
        self.dealer = ConnectionDealer(self._listener, self.slots, self.lock)
        self.served: list[dict] = []  # the closed streams' stats the workers reported as they stopped
        self.respawns = 0
        self._phase = "starting"  # then "serving", then "stopping"
        self._supervisor = threading.Thread(target=self._supervise, name="worker-supervisor", daemon=True)

    @property
    def processes(self) -> list[multiprocessing.process.BaseProcess]:
        """Each slot's current worker process."""
        return [slot.process for slot in self.slots]

    def start(self) -> Workers:
        """Start every worker, wait until each is ready, then deal connections; a worker that ends before it was
        ever ready stops the others and raises its error (one that ends after its ready report is started again,
        as while serving)."""
        self.slots.extend(WorkerSlot(index, *self._spawn(index)) for index in range(self.count))
        deadline = time.monotonic() + READY_TIMEOUT_S
        try:
            while not all(slot.ready for slot in self.slots):
                if time.monotonic() > deadline:
                    raise UserError(f"the workers were not all ready within {READY_TIMEOUT_S:.0f} s")
                self._watch(WATCH_S)
                self._respawn_due()
        except BaseException:
            self.stop()
            raise
        self._phase = "serving"
        self.dealer.start()
        self._supervisor.start()
        return self

    def stop(self) -> list[dict]:
        """Stop dealing, ask each worker to close its streams (killing any still running after
        :data:`STOP_TIMEOUT_S`); returns the closed streams' stats of all."""
        self.dealer.close()
        self._phase = "stopping"
        if self._supervisor.ident is not None:
            self._supervisor.join()
        for slot in self.slots:
            slot.respawn_at = None
            if slot.running:
                with suppress(OSError):
                    slot.channel.shutdown(socket.SHUT_WR)  # the worker reads the end of file: stop
        deadline = time.monotonic() + STOP_TIMEOUT_S
        while any(slot.running for slot in self.slots) and time.monotonic() < deadline:
            self._watch(min(WATCH_S, max(deadline - time.monotonic(), 0.0)))
        for slot in self.slots:
            if slot.running:
                logger.warning("worker-%d (pid %s) did not stop within %.0f s; killing it", slot.index,
                               slot.process.pid, STOP_TIMEOUT_S)
                slot.process.kill()
                slot.process.join(KILL_TIMEOUT_S)
            slot.channel.close()
        for connection in [*self.dealer.returned, *(c for slot in self.slots for c in slot.untaken)]:
            connection.close()
        self.token_failures.unlink(missing_ok=True)
        return self.served

    # ---- the supervisor (the caller's thread while starting and stopping, its own thread while serving) ----
    def _spawn(self, index: int) -> tuple[multiprocessing.process.BaseProcess, socket.socket]:
        """A started worker process for slot ``index`` and the parent's end of its socket pair."""
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        process = self._context.Process(target=run_worker, args=(*self._worker_args, theirs), name=f"worker-{index}")
        process.start()
        theirs.close()  # the worker holds its own copy now
        logger.info("worker-%d started (pid %d)", index, process.pid)
        return process, ours

    def _supervise(self) -> None:
        while self._phase == "serving":
            self._watch(WATCH_S)
            self._respawn_due()

    def _watch(self, timeout_s: float) -> None:
        """Wait up to ``timeout_s`` for a worker's report or end, and handle each that came."""
        waiting = {}
        for slot in self.slots:
            if slot.running:
                waiting[slot.channel] = waiting[slot.process.sentinel] = slot
        for ready in multiprocessing.connection.wait(list(waiting), timeout_s):
            slot = waiting[ready]
            if not slot.running:  # its channel and sentinel both woke this wait
                continue
            if ready is slot.channel and self._read(slot):
                continue
            self._ended(slot)

    def _read(self, slot: WorkerSlot, flags: int = 0) -> bool:
        """Handle the reports waiting on ``slot``'s channel; False at its end of file (the worker is ending) and,
        with ``MSG_DONTWAIT`` in ``flags``, when nothing is waiting."""
        try:
            data = slot.channel.recv(READ_BYTES, flags)
        except OSError:  # BlockingIOError included
            return False
        for kind, detail in slot.reports(data):
            self._report(slot, kind, detail)
        return bool(data)

    def _report(self, slot: WorkerSlot, kind: str, detail: object) -> None:
        with self.lock:
            if kind == "ready":
                slot.ready, slot.ready_at = True, time.monotonic()
                self.lock.notify_all()  # a connection may be waiting for a ready worker
                logger.info("worker-%d ready (pid %d)", slot.index, detail)
            elif kind == "took" and slot.untaken:
                slot.untaken.popleft().close()  # the worker holds its own copy now
            elif kind == "closed":
                slot.open = max(slot.open - 1, 0)
            elif kind == "served":
                self.served.extend(detail)
            elif kind == "error":
                slot.error = detail

    def _ended(self, slot: WorkerSlot) -> None:
        """``slot``'s worker has ended: read what it reported last, then schedule its replacement; a worker that
        ends before it was ever ready (a bad model, a port in use) stops the run with its error."""
        slot.process.join(KILL_TIMEOUT_S)
        if slot.process.is_alive():  # its channel ended but it did not: a replacement must not run beside it
            slot.process.kill()
            slot.process.join(KILL_TIMEOUT_S)
        while self._read(slot, socket.MSG_DONTWAIT):  # its last reports (the served streams) before its end
            pass
        with self.lock:
            slot.running = slot.ready = False
            held, slot.open = slot.open, 0
            untaken = list(slot.untaken)
            slot.untaken.clear()
        slot.channel.close()
        if self._phase == "serving":
            self.dealer.returned.extend(untaken)  # passed in the instant it died: dealt again
        else:
            for connection in untaken:
                connection.close()
        how = slot.error or how_it_ended(slot.process.exitcode)
        if self._phase == "starting" and slot.ready_at is None:
            raise UserError(slot.error or f"worker-{slot.index} ended before it was ready ({how})")
        if self._phase == "stopping":
            return
        steady = slot.ready_at is not None and time.monotonic() - slot.ready_at >= STEADY_S
        slot.failures = 0 if steady else slot.failures
        delay = min(RESPAWN_FIRST_S * 2 ** slot.failures, RESPAWN_MAX_S)
        slot.failures += 1
        slot.respawn_at = time.monotonic() + delay
        logger.warning("worker-%d (pid %d) ended (%s) holding %d connections (%d it had not taken are dealt again); "
                       "a new one starts in %.0f s", slot.index, slot.process.pid, how, held - len(untaken),
                       len(untaken), delay)

    def _respawn_due(self) -> None:
        """Start the replacement of each dead worker whose back-off is over."""
        for slot in self.slots:
            if slot.respawn_at is not None and time.monotonic() >= slot.respawn_at:
                process, channel = self._spawn(slot.index)
                with self.lock:
                    slot.process, slot.channel, slot.running = process, channel, True
                    slot.respawn_at, slot.ready_at, slot.error = None, None, None
                    slot.pending.clear()
                self.respawns += 1
