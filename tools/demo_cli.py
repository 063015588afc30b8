"""``gesturecast demo``: the bundled sample through the live engine (no arguments needed), then a preview."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

from gesturecast.bridges.vmc import VMC_DEFAULT_PORT
from gesturecast.bridges.vmc_roles import MARIONETTE
from gesturecast.bridges.websocket_server import WS_DEFAULT_PORT
from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.realtime.audio.cli import open_source
from gesturecast.realtime.audio.files import PACKAGED_SAMPLE
from gesturecast.realtime.engine import EngineReport, LiveEngine
from gesturecast.realtime.engine_cli import exit_status, raise_output_errors, summary_line
from gesturecast.realtime.engine_setup import add_generation_arguments, build_outputs, build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.scheduler import SchedulerConfig
from gesturecast.realtime.timing.status import StatusLine

logger = logging.getLogger(__name__)

DEMO_OUT = Path("out/demo")


def register(subparsers: argparse._SubParsersAction) -> None:
    demo = subparsers.add_parser("demo", help="the bundled sample through the live engine (no arguments needed)")
    add_generation_arguments(demo)
    demo.add_argument("--out", type=Path, default=DEMO_OUT, help="folder for the BVH, preview and latency JSON")
    demo.set_defaults(func=run_demo)


def run_demo(args: argparse.Namespace) -> int:
    """Bundled sample at real-time pace → VMC on 127.0.0.1:39539 + WebSocket viewer + BVH + rendered preview."""
    args.input, args.pace, args.block_size = str(PACKAGED_SAMPLE), "realtime", 512
    args.vmc, args.osc, args.osc_frame = f"127.0.0.1:{VMC_DEFAULT_PORT}", None, "unity"
    args.vmc_role, args.vmc_bones = MARIONETTE, None
    args.ws, args.host, args.token, args.fps = WS_DEFAULT_PORT, "127.0.0.1", None, 30
    args.token_file, args.allow_origin, args.avatar = None, [], None  # avatar: the default lookup (docs/bridges.md)
    args.bvh = args.out / "demo.bvh"
    clock = MonotonicClock()
    session = build_session(args, clock)
    outputs = _demo_outputs(args, session, clock)
    sys.stdout.write(session.budget.describe() + "\n")
    sys.stdout.write(f"streaming VMC to 127.0.0.1:{VMC_DEFAULT_PORT}; viewer at http://127.0.0.1:{args.ws}/\n")
    engine = LiveEngine(session, open_source(args, clock), outputs.send, clock, SchedulerConfig(), StatusLine(clock))
    try:
        report = engine.run()
    finally:
        outputs.close()
    raise_output_errors(outputs)
    if report.interrupted:  # no preview: Ctrl-C should end the run now, not after rendering
        _write_latency(args, report)
        return exit_status(report)
    _write_demo_results(args, report)
    return 0


def _demo_outputs(args: argparse.Namespace, session, clock):
    """The demo's outputs; if the viewer port is taken, the viewer moves to a free port instead of failing."""
    try:
        return build_outputs(args, session, clock)
    except UserError as error:
        logger.warning("%s; using a free port for the viewer", error)
        args.ws = 0
        return build_outputs(args, session, clock)


def _write_demo_results(args: argparse.Namespace, report: EngineReport) -> None:
    from gesturecast.models.motion.retarget import load_motion_file
    from gesturecast.tools.render.animation import render_positions

    motion = load_motion_file(args.bvh, keep_hands=True)  # the recorded fingers are drawn too
    preview = render_positions(motion.positions(), motion.skeleton.parents, args.out / "demo.gif",
                               fps=motion.fps, title=f"gesturecast demo - style {args.style}",  # ASCII font
                               names=motion.skeleton.names)
    _write_latency(args, report)
    sys.stdout.write(f"wrote {preview}\n")


def _write_latency(args: argparse.Namespace, report: EngineReport) -> None:
    """latency.json and the summary line (both also after Ctrl-C, with the BVH recorded so far)."""
    write_text_atomic(args.out / "latency.json", json.dumps(report.to_dict(), indent=2) + "\n")
    sys.stdout.write(summary_line(report) + "\n")
    sys.stdout.write(f"wrote {args.bvh} and {args.out / 'latency.json'}\n")
