"""A websockets server on its own event-loop thread, shared by the viewer bridge and ``gesturecast serve``.

The caller's thread starts and closes it; handlers and everything scheduled with :attr:`loop` run on
the loop thread. A busy port or a refused address is a one-line :class:`UserError`.
"""

from __future__ import annotations

import asyncio
import errno
import threading
from collections.abc import Awaitable, Callable

from websockets.asyncio.server import Server, ServerConnection, serve

from gesturecast.errors import UserError

START_TIMEOUT_S = 10.0


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

    def start(self, handler: Callable[[ServerConnection], Awaitable[None]], **serve_options) -> None:
        self._thread.start()
        try:
            asyncio.run_coroutine_threadsafe(self._open(handler, serve_options), self.loop).result(START_TIMEOUT_S)
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

    async def _open(self, handler, serve_options: dict) -> None:
        # no permessage-deflate: pose frames are float32 rotations that deflate barely shrinks, and compressing
        # every frame for every client took about 8 % of a busy server's CPU (docs/serve.md)
        self._server = await serve(handler, self.host, self.port, **{"compression": None, **serve_options})
        self.port = self._server.sockets[0].getsockname()[1]

    async def _close_server(self) -> None:
        self._server.close()
        await self._server.wait_closed()

    def _stop_loop(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(self.stop_timeout_s)
