"""``gesturecast demo``: the bundled sample through the live engine (no arguments needed), then a preview."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from dataclasses import replace
from pathlib import Path

from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.output_settings import Outputs
from gesturecast.bridges.vmc import VMC_DEFAULT_PORT
from gesturecast.bridges.websocket_server import WS_DEFAULT_PORT, WebSocketBridge
from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.models.audio.files import PACKAGED_SAMPLE
from gesturecast.realtime.audio.sources import PacedFileSource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.engine_cli import exit_status, raise_output_errors, summary_line
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.run.engine import EngineReport, LiveEngine
from gesturecast.realtime.run.engine_setup import build_outputs, build_session
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.scheduler import SchedulerConfig
from gesturecast.realtime.timing.status import StatusLine
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

DEMO_OUT = Path("out/demo")
DEMO_VMC = f"127.0.0.1:{VMC_DEFAULT_PORT}"
DEMO_BLOCK = 512  # samples per chunk, as a microphone delivers them


def register(subparsers: argparse._SubParsersAction) -> None:
    demo = subparsers.add_parser("demo", help="the bundled sample through the live engine (no arguments needed)")
    add_generation_arguments(demo)
    demo.add_argument("--out", type=Path, default=DEMO_OUT, help="folder for the BVH, preview and latency JSON")
    demo.add_argument("--vmc", metavar="HOST[:PORT]", default=DEMO_VMC,
                      help="VMC receiver (VSeeFace, Warudo, EVMC4U) to stream to (default %(default)s)")
    demo.set_defaults(func=run_demo)


def run_demo(args: argparse.Namespace) -> int:
    """Bundled sample at real-time pace → VMC (127.0.0.1:39539 unless --vmc) + WebSocket viewer + BVH + preview.

    When nothing listens for VMC there, the VMC bridge says so once and counts the datagrams nobody received."""
    settings, bvh = settings_from_args(args), args.out / "demo.bvh"
    clock = MonotonicClock()
    session = build_session(settings, clock)
    outputs = _demo_outputs(Outputs(vmc=args.vmc, ws=WS_DEFAULT_PORT, bvh=bvh), settings, session, clock)
    sys.stdout.write(session.budget.describe() + "\n")
    sys.stdout.write(f"streaming VMC to {args.vmc}; viewer at {_viewer_url(outputs)}\n")
    source = PacedFileSource(PACKAGED_SAMPLE, chunk_samples=DEMO_BLOCK, clock=clock)
    engine = LiveEngine(session, source, outputs.send, clock, SchedulerConfig(), StatusLine(clock))
    try:
        report = engine.run()
    finally:
        outputs.close()
    report.outputs = outputs.counters()  # in the summary: e.g. the VMC datagrams nobody received
    raise_output_errors(outputs)
    if report.interrupted:  # no preview: Ctrl-C should end the run now, not after rendering
        _write_latency(args.out, bvh, report)
        return exit_status(report)
    _write_demo_results(args.out, bvh, settings, report)
    return 0


def _demo_outputs(outputs: Outputs, settings: Settings, session: GestureSession, clock: Clock) -> BridgeFanout:
    """The demo's outputs; if the viewer port is taken, the viewer moves to a free port instead of failing."""
    try:
        return build_outputs(outputs, settings, session, clock)
    except UserError as error:
        logger.warning("%s; using a free port for the viewer", error)
        return build_outputs(replace(outputs, ws=0), settings, session, clock)


def _viewer_url(outputs: BridgeFanout) -> str:
    """The address the viewer really listens on (a free port when the default one was taken)."""
    return next(bridge.url for bridge in outputs.bridges if isinstance(bridge, WebSocketBridge))


def _write_demo_results(out: Path, bvh: Path, settings: Settings, report: EngineReport) -> None:
    from gesturecast.models.motion.retarget import load_motion_file
    from gesturecast.tools.render.animation import render_positions

    motion = load_motion_file(bvh, keep_hands=True)  # the recorded fingers are drawn too
    preview = render_positions(motion.positions(), motion.skeleton.parents, out / "demo.gif",
                               fps=motion.fps, title=f"gesturecast demo - style {settings.style}",  # ASCII font
                               names=motion.skeleton.names)
    _write_latency(out, bvh, report)
    sys.stdout.write(f"wrote {preview}\n")


def _write_latency(out: Path, bvh: Path, report: EngineReport) -> None:
    """latency.json and the summary line (both also after Ctrl-C, with the BVH recorded so far)."""
    write_text_atomic(out / "latency.json", json.dumps(report.to_dict(), indent=2) + "\n")
    sys.stdout.write(summary_line(report) + "\n")
    sys.stdout.write(f"wrote {bvh} and {out / 'latency.json'}\n")
