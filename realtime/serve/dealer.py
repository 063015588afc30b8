"""``serve --workers N``: the parent accepts every connection and deals it to the worker holding the fewest.

The kernel's ``SO_REUSEPORT`` balancing hashes each connection's addresses, so twenty streams over two workers
split 10/10 only sometimes: 13/7 is common, and the worker with 13 runs out of its one core's worth of interpreter
time while the other idles (docs/serve.md). Here the parent process (it loads no model) accepts on the public port
and passes each accepted socket over a Unix socket pair (``SCM_RIGHTS``) to the worker with the fewest open
connections; the worker serves it as if it had accepted it (:meth:`GestureServer.adopt`) and counts it down in the
shared tally when it closes. The counts are of open connections, started or not.
"""

from __future__ import annotations

import logging
import socket
import threading
from multiprocessing.sharedctypes import SynchronizedArray

from gesturecast.realtime.serve.server import GestureServer

logger = logging.getLogger(__name__)

DEAL = b"c"  # the one byte that carries each passed socket
ACCEPT_POLL_S = 0.25  # how often the dealer looks for its stop while no client connects
STOP_TIMEOUT_S = 5.0


def fewest(counts: SynchronizedArray) -> int:
    """Index of the worker with the fewest open connections (the first of equals)."""
    with counts.get_lock():
        values = list(counts)
    return values.index(min(values))


def count(counts: SynchronizedArray, index: int, change: int) -> None:
    with counts.get_lock():
        counts[index] += change


class ConnectionDealer:
    """Parent side: a thread that accepts on ``listener`` and passes each connection to a worker's channel."""

    def __init__(self, listener: socket.socket, channels: list[socket.socket], counts: SynchronizedArray) -> None:
        self.listener = listener
        self.channels = channels
        self.counts = counts
        self.dealt = [0] * len(channels)  # connections passed to each worker, for the summary
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._deal, name="connection-dealer", daemon=True)

    def start(self) -> ConnectionDealer:
        self.listener.settimeout(ACCEPT_POLL_S)
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop accepting (clients that connect after this are refused by the closed port) and close the channels
        (each worker's receiver then ends)."""
        self._stop.set()
        if self._thread.ident is not None:  # started
            self._thread.join(STOP_TIMEOUT_S)
        self.listener.close()
        for channel in self.channels:
            channel.close()

    def _deal(self) -> None:
        while not self._stop.is_set():
            try:
                connection, _ = self.listener.accept()
            except TimeoutError:
                continue
            except OSError as error:  # the listener is gone: nothing more to deal
                logger.warning("serve --workers stopped accepting: %s", error)
                return
            with connection:  # the worker holds its own copy once passed; the parent's is closed here
                self._pass(connection)

    def _pass(self, connection: socket.socket) -> None:
        index = fewest(self.counts)
        count(self.counts, index, +1)  # counted before it is passed: the worker may answer before this thread runs on
        self.dealt[index] += 1
        try:
            socket.send_fds(self.channels[index], [DEAL], [connection.fileno()])
        except OSError as error:  # the worker is gone; the client sees its connection closed
            count(self.counts, index, -1)
            self.dealt[index] -= 1
            logger.warning("could not pass a connection to worker %d: %s", index, error)


def receive_connections(channel: socket.socket, server: GestureServer, counts: SynchronizedArray,
                        index: int) -> None:
    """Worker side: a thread that serves every connection the parent passes on ``channel`` and counts it down in
    ``counts[index]`` when it closes; it ends when the parent closes the channel."""

    def closed(_) -> None:
        count(counts, index, -1)

    def receive() -> None:
        while True:
            try:
                _, fds, _, _ = socket.recv_fds(channel, len(DEAL), 1)
            except OSError:
                return
            if not fds:  # end of file: the parent is gone or stopping
                return
            server.adopt(socket.socket(fileno=fds[0])).add_done_callback(closed)

    threading.Thread(target=receive, name="connection-receiver", daemon=True).start()
