"""A websockets server on its own event-loop thread, shared by the viewer bridge and ``gesturecast serve``.

The caller's thread starts and closes it; handlers and everything scheduled with :attr:`loop` run on
the loop thread. A busy port or a refused address is a one-line :class:`UserError`. Started on a given listening
``sock`` instead of ``host:port``, it can also :meth:`~ThreadedListener.adopt` TCP connections that another process
accepted (``serve --workers``: the parent deals each connection to the worker with the fewest).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import errno
import os
import socket
import tempfile
import threading
from collections.abc import Awaitable, Callable

from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.server import ServerProtocol

from gesturecast.errors import UserError

START_TIMEOUT_S = 10.0
DEFAULT_MAX_SIZE = 2**20  # websockets' own limit on an incoming message, when the caller names none


def private_listener() -> socket.socket:
    """A listening socket nobody can connect to, for a server whose connections all come through
    :meth:`ThreadedListener.adopt`: a Unix socket bound in a private folder, whose name is removed at once (an
    abstract name would be open to every user of the host)."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    with tempfile.TemporaryDirectory(prefix="gesturecast-") as folder:  # mode 0700
        listener.bind(os.path.join(folder, "s"))
        listener.listen()
    return listener


class ThreadedListener:
    """Listens on ``host:port`` (0 = any free port; :attr:`port` is the bound one after :meth:`start`)."""

    def __init__(self, host: str, port: int, thread_name: str, stop_timeout_s: float, port_flag: str) -> None:
        self.host = host
        self.port = port
        self.port_flag = port_flag  # the command-line flag that picks this port, named in the busy-port error
        self.stop_timeout_s = stop_timeout_s
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, name=thread_name, daemon=True)
        self._server: Server | None = None
        self._max_size: int | None = None  # the largest message a client may send (adopted connections too)

    def start(self, handler: Callable[[ServerConnection], Awaitable[None]], sock: socket.socket | None = None,
              **serve_options) -> None:
        """Serve ``handler`` on ``host:port``, or on the listening ``sock`` when one is given."""
        self._thread.start()
        try:
            opening = self._open(handler, sock, serve_options)
            asyncio.run_coroutine_threadsafe(opening, self.loop).result(START_TIMEOUT_S)
        except OSError as error:
            self._stop_loop()
            if error.errno == errno.EADDRINUSE:
                raise UserError(f"port {self.port} on {self.host} is in use; "
                                f"pick another with {self.port_flag}") from None
            raise UserError(f"cannot listen on {self.host}:{self.port}: {error.strerror}") from None

    def close(self) -> None:
        if self._server is not None:
            asyncio.run_coroutine_threadsafe(self._close_server(), self.loop).result(self.stop_timeout_s)
        self._stop_loop()

    def adopt(self, connection: socket.socket) -> concurrent.futures.Future:
        """Serve one TCP connection accepted elsewhere as if this server had accepted it (the same handler, access
        check and message limit); returns a future done when the connection has closed."""
        return asyncio.run_coroutine_threadsafe(self._adopt(connection), self.loop)

    async def _open(self, handler, sock: socket.socket | None, serve_options: dict) -> None:
        # no permessage-deflate: pose frames are float32 rotations that deflate barely shrinks, and compressing
        # every frame for every client took about 8 % of a busy server's CPU (docs/serve.md)
        options = {"compression": None, **serve_options}
        self._max_size = options.get("max_size", DEFAULT_MAX_SIZE)
        if sock is not None:  # started quietly: the websockets logger would print the private socket's old name
            self._server = await serve(handler, sock=sock, start_serving=False, **options)
            await self._server.start_serving()
            return
        self._server = await serve(handler, self.host, self.port, **options)
        self.port = self._server.sockets[0].getsockname()[1]

    async def _adopt(self, accepted: socket.socket) -> None:
        # what serve() builds for a connection it accepts itself: without compression, with the same size limit
        protocol = ServerProtocol(max_size=self._max_size, logger=self._server.logger)
        connection = ServerConnection(protocol, self._server)
        await self.loop.connect_accepted_socket(lambda: connection, accepted)
        await connection.wait_closed()

    async def _close_server(self) -> None:
        self._server.close()
        await self._server.wait_closed()

    def _stop_loop(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(self.stop_timeout_s)
