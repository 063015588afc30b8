"""``serve --workers N``: the parent accepts every connection and deals it to the worker holding the fewest.

The kernel's ``SO_REUSEPORT`` balancing hashes each connection's addresses, so twenty streams over two workers
split 10/10 only sometimes: 13/7 is common, and the worker with 13 runs out of its one core's worth of interpreter
time while the other idles (docs/serve.md). Here the parent process (it loads no model) accepts on the public port
and passes each accepted socket over a Unix socket pair (``SCM_RIGHTS``) to the ready worker with the fewest open
connections; the worker serves it as if it had accepted it (:meth:`GestureServer.adopt`).

The socket pair is the only link between the two processes (no shared memory, lock or event that a killed process
could leave held). Parent → worker: one byte per passed socket; the parent's end shut for writing means "stop"
(its end closed by the kernel, when the parent is killed, reads the same). Worker → parent: one JSON line per
report: ``ready`` (its pid), ``error`` (why it could not start), ``closed`` (one of its connections ended: the
parent counts it down) and ``served`` (the closed streams' stats, when it stops), and ``took`` as it takes each
passed socket: until then the parent keeps its own copy, and a worker that dies before taking some (passed in the
instant it was killed) has them dealt again to another.
"""

from __future__ import annotations

import json
import logging
import socket
import threading
from collections import deque
from dataclasses import dataclass, field
from multiprocessing.process import BaseProcess

from gesturecast.realtime.serve.server import GestureServer

logger = logging.getLogger(__name__)

DEAL = b"c"  # the one byte that carries each passed socket
ACCEPT_POLL_S = 0.25  # how often the dealer looks for its stop while no client connects
WAIT_FOR_WORKER_S = 15.0  # a connection that arrives while no worker is ready waits this long for one
STOP_TIMEOUT_S = 5.0


@dataclass(eq=False)
class WorkerSlot:
    """One worker's place in the parent: its current process, the parent's end of its socket pair and the
    connections it holds open; a respawned worker takes the same slot (index) with a new process and pair."""

    index: int
    process: BaseProcess
    channel: socket.socket
    running: bool = True  # its process has not been seen to end
    ready: bool = False  # reported ready and not known dead: the dealer may pass it connections
    open: int = 0  # connections passed and not reported closed
    ready_at: float | None = None  # monotonic time of its ready report
    error: str | None = None  # what it reported when it could not start
    failures: int = 0  # ends in a row, each before it had been ready STEADY_S (the respawn back-off doubles)
    respawn_at: float | None = None  # monotonic time its replacement starts, while it is dead
    pending: bytearray = field(default_factory=bytearray)  # report bytes not yet ending in a newline
    untaken: deque[socket.socket] = field(default_factory=deque)  # passed, the worker's "took" not yet read

    def reports(self, data: bytes) -> list[tuple[str, object]]:
        """The complete (kind, detail) reports in ``data`` (appended to what came before)."""
        self.pending += data
        if b"\n" not in self.pending:
            return []
        *lines, rest = bytes(self.pending).split(b"\n")
        self.pending = bytearray(rest)
        return [tuple(json.loads(line)) for line in lines if line]


def fewest(slots: list[WorkerSlot]) -> WorkerSlot | None:
    """The ready worker with the fewest open connections (the first of equals); None when none is ready."""
    ready = [slot for slot in slots if slot.ready]
    return min(ready, key=lambda slot: slot.open) if ready else None


class ConnectionDealer:
    """Parent side: a thread that accepts on ``listener`` and passes each connection to a ready worker (``slots``,
    guarded by ``lock``: the supervisor replaces a dead worker's process and channel under it, and notifies it when
    a worker becomes ready)."""

    def __init__(self, listener: socket.socket, slots: list[WorkerSlot], lock: threading.Condition) -> None:
        self.listener = listener
        self.slots = slots
        self.lock = lock
        self.dealt: list[int] = []  # connections passed to each worker slot, for the summary
        self.unserved = 0  # connections closed because no worker was ready
        self.returned: deque[socket.socket] = deque()  # passed to a worker that died before taking them
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._deal, name="connection-dealer", daemon=True)

    def start(self) -> ConnectionDealer:
        self.dealt = [0] * len(self.slots)
        self.listener.settimeout(ACCEPT_POLL_S)
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop accepting (clients that connect after this are refused by the closed port)."""
        with self.lock:
            self._stop.set()
            self.lock.notify_all()  # a connection waiting for a worker gives up now
        if self._thread.ident is not None:  # started
            self._thread.join(STOP_TIMEOUT_S)
        self.listener.close()

    def _deal(self) -> None:
        while not self._stop.is_set():
            while self.returned:
                self._pass(self.returned.popleft())
            try:
                connection, _ = self.listener.accept()
            except TimeoutError:
                continue
            except OSError as error:  # the listener is gone: nothing more to deal
                logger.warning("serve --workers stopped accepting: %s", error)
                return
            self._pass(connection)

    def _pass(self, connection: socket.socket) -> None:
        """Pass ``connection`` to the ready worker with the fewest (it stays in the slot's ``untaken`` until the
        worker reports it took it); one that cannot take it (it died a moment ago) is marked not ready and the next
        is tried. With none ready it waits up to WAIT_FOR_WORKER_S for one (the clients behind it wait in the listen
        queue), then the client sees its connection closed."""
        for _ in self.slots:
            with self.lock:
                self.lock.wait_for(lambda: self._stop.is_set() or fewest(self.slots) is not None, WAIT_FOR_WORKER_S)
                slot = fewest(self.slots)
                if slot is None:
                    break
                slot.open += 1  # counted before it is passed: the worker may report it closed before we go on
                self.dealt[slot.index] += 1
                slot.untaken.append(connection)
                channel = slot.channel
            try:
                socket.send_fds(channel, [DEAL], [connection.fileno()])
                return
            except OSError as error:  # gone: the supervisor respawns it when it sees the process end
                with self.lock:
                    slot.open, slot.ready = max(slot.open - 1, 0), False
                    self.dealt[slot.index] -= 1
                    if connection not in slot.untaken:  # the supervisor saw it die and returned it already
                        return
                    slot.untaken.remove(connection)
                logger.warning("could not pass a connection to worker-%d (%s); trying another", slot.index, error)
        connection.close()
        if not self._stop.is_set():  # stopping closes it without a word
            self.unserved += 1
            logger.warning("no worker became ready within %.0f s; closed a connection (%d so far)", WAIT_FOR_WORKER_S,
                           self.unserved)


class WorkerLink:
    """Worker side of the socket pair: reports to the parent (any thread) and the connections it passes."""

    def __init__(self, channel: socket.socket) -> None:
        self.channel = channel
        self.stopped = threading.Event()  # set when the parent says stop, or is gone
        self._lock = threading.Lock()

    def report(self, kind: str, detail: object = None) -> None:
        """One JSON line to the parent; nothing when the parent is gone (the worker is stopping then anyway)."""
        line = json.dumps([kind, detail]).encode() + b"\n"
        try:
            with self._lock:
                self.channel.sendall(line)
        except OSError:
            self.stopped.set()

    def receive_connections(self, server: GestureServer) -> None:
        """A thread that serves every connection the parent passes and reports each one closed; it ends, setting
        :attr:`stopped`, at the end of file: the parent stops the worker, or is gone."""

        def closed(_) -> None:
            self.report("closed")

        def receive() -> None:
            try:
                while True:
                    data, fds, _, _ = socket.recv_fds(self.channel, len(DEAL), 1)
                    if not data:  # end of file
                        return
                    for fd in fds:
                        server.adopt(socket.socket(fileno=fd)).add_done_callback(closed)
                        self.report("took")
            except OSError:
                return
            finally:
                self.stopped.set()

        threading.Thread(target=receive, name="connection-receiver", daemon=True).start()
