"""A running ``serve`` server from :class:`Settings` (every stream's defaults) and a :class:`ServeConfig`."""

from __future__ import annotations

import gc
import sys

from gesturecast.errors import UserError
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import Clock
from gesturecast.settings import Settings

SWITCH_INTERVAL_S = 0.001  # 20 streams, two cores: late frames 48-132 at 1 ms against 172-529 at 5 ms


def start_server(settings: Settings, config: ServeConfig, clock: Clock) -> GestureServer:
    """The server, listening; the default settings are checked on the model first (its look-ahead, the default
    style and body parts, by making the default generator on the shared denoiser), so a bad one fails in one line
    before any port is opened."""
    if config.max_streams < 1:
        raise UserError(f"--max-streams must be at least 1, got {config.max_streams}")
    sessions = StreamSessions(settings, load_bundle(settings.model), clock, config.max_streams)
    try:
        sessions.factory.generator()
        server = GestureServer(sessions, clock, config).start()
    except UserError:
        sessions.close()
        raise
    tune_for_streams()
    return server


def tune_for_streams() -> None:
    """The serving process's interpreter tuned for many stream threads (docs/serve.md, "each connection to the
    worker holding the fewest"): a thread that waits for the interpreter lock gets it within SWITCH_INTERVAL_S rather
    than Python's 5 ms, and what exists now (the model, the sessions' shared parts) moves out of the garbage
    collector's view, so its full collections in the middle of streams stay short."""
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    gc.freeze()
