"""The flags of ``gesturecast serve`` and the :class:`ServeConfig` they give, shared by ``serve``, ``serve --ray``, a
Ray Serve config's application builder and ``bench serve`` (below all of them: none imports another's command)."""

from __future__ import annotations

import argparse

from gesturecast.arguments import port_number
from gesturecast.bridges.coords import FRAMES
from gesturecast.realtime.cli_flags import add_access_arguments, add_generation_arguments
from gesturecast.realtime.serve.server import SERVE_DEFAULT_PORT, ServeConfig
from gesturecast.realtime.serve.stream import StreamConfig
from gesturecast.settings import OUTPUT_RATES


def add_serve_arguments(parser: argparse.ArgumentParser) -> None:
    add_generation_arguments(parser)
    group = parser.add_argument_group("server")
    group.add_argument("--host", default="127.0.0.1", help="listen address (beyond loopback needs --token)")
    group.add_argument("--port", type=port_number(allow_any=True), default=SERVE_DEFAULT_PORT,
                       help="WebSocket port (0 = any free port)")
    add_access_arguments(group)
    group.add_argument("--max-streams", type=int, default=ServeConfig.max_streams, help="concurrent streams allowed")
    group.add_argument("--coordinate-frame", choices=tuple(FRAMES), default="internal", help="frame of sent poses")
    group.add_argument("--fps", type=int, choices=OUTPUT_RATES, default=30, help="output rate (60 = slerp upsampling)")
    group.add_argument("--workers", type=int, default=1, metavar="N",
                       help="server processes behind the port, each with its own model and --max-streams slots; "
                            "each connection goes to the one holding fewest (one process uses about one core for the "
                            "streams' Python work: 4 for many streams on 2 cores; Linux)")


def serve_config(args: argparse.Namespace, token: str | None) -> ServeConfig:
    """The server's listening and stream options from the flags."""
    return ServeConfig(host=args.host, port=args.port, token=token, max_streams=args.max_streams,
                       coordinate_frame=args.coordinate_frame, stream=StreamConfig(output_fps=float(args.fps)),
                       allow_origins=tuple(args.allow_origin))
