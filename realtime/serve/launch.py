"""A running ``serve`` server from :class:`Settings` (every stream's defaults) and a :class:`ServeConfig`."""

from __future__ import annotations

from gesturecast.errors import UserError
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import Clock
from gesturecast.settings import Settings


def start_server(settings: Settings, config: ServeConfig, clock: Clock) -> GestureServer:
    """The server, listening; the settings are checked first by building one session (the model, its look-ahead
    and the default style), so a bad one fails in one line before any port is opened."""
    if config.max_streams < 1:
        raise UserError(f"--max-streams must be at least 1, got {config.max_streams}")
    probe = build_session(settings, clock)
    sessions = StreamSessions(probe.bundle, probe.generator.settings, probe.budget, clock, config.max_streams,
                              probe.config)
    try:
        return GestureServer(sessions, clock, config).start()
    except UserError:
        sessions.close()
        raise
