"""``gesturecast serve``: N concurrent streams over WebSocket with batched inference (docs/serve.md)."""

from __future__ import annotations

import argparse
import logging
import sys
import threading
from collections.abc import Callable

from gesturecast import stop_signals
from gesturecast.errors import INTERRUPTED_EXIT
from gesturecast.realtime.cli_flags import server_token, settings_from_args
from gesturecast.realtime.serve.cli_args import add_serve_arguments, serve_config
from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.ray_cli import add_ray_arguments, ray_serving
from gesturecast.realtime.serve.server import GestureServer
from gesturecast.realtime.serve.workers import Workers
from gesturecast.realtime.timing.clock import Clock, MonotonicClock

logger = logging.getLogger(__name__)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("serve", help="many avatars: audio in / poses out over WebSocket, batched")
    add_serve_arguments(parser)
    add_ray_arguments(parser)
    parser.set_defaults(func=run_serve)


def build_server(args: argparse.Namespace, clock: Clock) -> GestureServer:
    """The server for these flags (a missing token file fails before the model loads)."""
    config = serve_config(args, server_token(args))
    return start_server(settings_from_args(args), config, clock)


def run_serve(args: argparse.Namespace) -> int:
    if args.ray:
        return run_on_ray(args)
    if args.workers != 1:  # Workers refuses a count out of range
        return run_workers(args)
    server = build_server(args, MonotonicClock())

    def stop() -> list[dict]:
        server.close()
        return list(server.finished)

    return serve_until_stopped(f"{server.sessions.budget.describe()}\nstreams: {server.url}<id> "
                               f"(at most {args.max_streams})", stop)


def run_workers(args: argparse.Namespace) -> int:
    """``serve --workers N``: N server processes on one port until Ctrl-C (realtime/serve/workers.py)."""
    workers = Workers(settings_from_args(args), serve_config(args, server_token(args)), args.workers).start()
    url = f"ws://{args.host}:{workers.port}/stream/"
    return serve_until_stopped(f"{args.workers} server processes; streams: {url}<id> (at most {args.max_streams} "
                               "each)", workers.stop)


def serve_until_stopped(banner: str, stop: Callable[[], list[dict]]) -> int:
    """Print where streams go, serve until Ctrl-C, SIGTERM or SIGHUP, then ``stop`` (→ the closed streams' stats)
    and print one summary line over them."""
    sys.stdout.write(f"{banner}; Ctrl-C stops\n")
    sys.stdout.flush()
    try:
        wait_for_ctrl_c()
    finally:
        served = stop()
    sys.stdout.write(served_summary(served) + "\n")
    return INTERRUPTED_EXIT


def run_on_ray(args: argparse.Namespace) -> int:
    """``serve --ray``: the same streams on Ray Serve replicas until Ctrl-C (docs/scale.md)."""
    with ray_serving(args) as where:
        sys.stdout.write(f"{where}; Ctrl-C stops\n")
        sys.stdout.flush()
        wait_for_ctrl_c()
    return INTERRUPTED_EXIT


def wait_for_ctrl_c() -> None:
    """Block the main thread (the server runs on its own) until Ctrl-C, SIGTERM or SIGHUP."""
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        logger.info("%s: closing the streams", stop_signals.stopped_by())


def served_summary(streams: list[dict]) -> str:
    """One line over the streams closed while serving (those still remembered: at most --max-streams)."""
    total = {key: sum(s[key] for s in streams) for key in ("audio_seconds", "frames", "deadline_misses",
                                                            "audio_dropped_samples")}
    return (f"stopped by {stop_signals.stopped_by()}: last {len(streams)} streams served: {total['frames']} frames "
            f"from {total['audio_seconds']:.1f} s of audio | deadline misses {total['deadline_misses']} | "
            f"audio drops {total['audio_dropped_samples']}")
