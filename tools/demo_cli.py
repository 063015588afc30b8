"""``gesturecast demo``: the bundled sample through the live engine (no arguments needed), then a preview.

It says what it does while it loads, prints the viewer's address before the sample plays, and ends with the sample
(``make demo`` runs it and must end by itself); ``--loop`` keeps the viewer and VMC going with the sample replayed
until Ctrl-C. The engine is imported when the demo runs: ``gesturecast demo --help`` answers without it.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from gesturecast.arguments import port_number
from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.output_settings import Outputs
from gesturecast.bridges.vmc import VMC_DEFAULT_PORT
from gesturecast.bridges.websocket_server import WS_DEFAULT_PORT, WebSocketBridge
from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.models.audio.files import PACKAGED_SAMPLE, AudioFileReader
from gesturecast.realtime.audio.sources import PacedFileSource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.engine_cli import exit_status, raise_output_errors, summary_line
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.scheduler import SchedulerConfig
from gesturecast.realtime.timing.status import StatusLine
from gesturecast.settings import Settings

if TYPE_CHECKING:
    from gesturecast.realtime.pose.session import GestureSession
    from gesturecast.realtime.run.engine import EngineReport

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
    demo.add_argument("--ws", metavar="PORT", type=port_number(allow_any=True),
                      help=f"port of the browser viewer (default {WS_DEFAULT_PORT}, or a free one when it is taken)")
    demo.add_argument("--audio", type=Path, default=PACKAGED_SAMPLE, metavar="FILE",
                      help="speech to play instead of the bundled sample (a WAV, FLAC, OGG or MP3 file)")
    demo.add_argument("--loop", action="store_true",
                      help="after the first run (the files written), replay the sample to the viewer and VMC until "
                           "Ctrl-C; without it the demo ends with the sample")
    demo.set_defaults(func=run_demo)


def run_demo(args: argparse.Namespace) -> int:
    """Bundled sample at real-time pace → VMC (127.0.0.1:39539 unless --vmc) + WebSocket viewer + BVH + preview; with
    --loop, then the sample again and again to the viewer and VMC until Ctrl-C.

    When nothing listens for VMC there, the VMC bridge says so once and counts the datagrams nobody received."""
    from gesturecast.realtime.run.engine_setup import build_session

    settings, clock = settings_from_args(args), MonotonicClock()
    seconds = AudioFileReader(args.audio).duration_s  # a file that cannot be played says so before the model loads
    _say("loading the model and the gesture lexicon…")
    session = build_session(settings, clock)
    _say(f"opening the outputs: VMC to {args.vmc}, the browser viewer, a BVH recording…")
    viewer_port = WS_DEFAULT_PORT if args.ws is None else args.ws
    live = _demo_outputs(Outputs(vmc=args.vmc, ws=viewer_port), settings, session, clock, free_port=args.ws is None)
    try:
        status = _play_and_record(args, settings, session, live, clock, seconds)
        if status == 0 and args.loop:
            status = _replay_until_interrupted(args.audio, session, live, clock)
    finally:
        live.close()
    raise_output_errors(live)
    return status


def _play_and_record(args: argparse.Namespace, settings: Settings, session: GestureSession, live: BridgeFanout,
                     clock: Clock, seconds: float) -> int:
    """The sample once to the live outputs and a BVH recording; then the preview and the latency JSON."""
    from gesturecast.realtime.run.engine import LiveEngine
    from gesturecast.realtime.run.engine_setup import build_outputs

    bvh = args.out / "demo.bvh"
    recorder = build_outputs(Outputs(bvh=bvh), settings, session, clock)
    outputs = BridgeFanout([*live.bridges, *recorder.bridges])
    _say(session.budget.describe())
    after = "replayed until Ctrl-C" if args.loop else "it closes when the sample ends; --loop keeps it up"
    _say(f"playing the {seconds:.0f} s sample; open the viewer now: {_viewer_url(live)} ({after})")
    engine = LiveEngine(session, _sample(args.audio, clock), outputs.send, clock, SchedulerConfig(), StatusLine(clock))
    try:
        report = engine.run()
    finally:
        recorder.close()
    report.outputs = outputs.counters()  # in the summary: e.g. the VMC datagrams nobody received
    raise_output_errors(recorder)
    if report.interrupted:  # no preview: Ctrl-C should end the run now, not after rendering
        _write_latency(args.out, bvh, report)
        return exit_status(report)
    _write_demo_results(args.out, bvh, settings, report)
    return 0


def _replay_until_interrupted(audio: Path, session: GestureSession, live: BridgeFanout, clock: Clock) -> int:
    """The sample again and again to the viewer and VMC, each time from a fresh stream, until Ctrl-C (130)."""
    from gesturecast.realtime.run.engine import LiveEngine

    _say(f"replaying the sample until Ctrl-C; viewer at {_viewer_url(live)}")
    while True:
        session.reset()
        report = LiveEngine(session, _sample(audio, clock), live.send, clock, SchedulerConfig(),
                            StatusLine(clock)).run()
        if report.interrupted:
            return exit_status(report)


def _sample(audio: Path, clock: Clock) -> PacedFileSource:
    """The sample (the bundled one unless --audio) at real-time pace, in microphone-sized chunks."""
    return PacedFileSource(audio, chunk_samples=DEMO_BLOCK, clock=clock)


def _say(line: str) -> None:
    """One progress line on stdout, shown at once (also when stdout is a pipe)."""
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def _demo_outputs(outputs: Outputs, settings: Settings, session: GestureSession, clock: Clock,
                  free_port: bool) -> BridgeFanout:
    """The demo's live outputs; with ``free_port`` (no --ws given), a taken viewer port moves the viewer to a free
    one instead of failing."""
    from gesturecast.realtime.run.engine_setup import build_outputs

    try:
        return build_outputs(outputs, settings, session, clock)
    except UserError:
        if not free_port:
            raise
        logger.warning("port %d is taken; the viewer uses a free port instead (--ws PORT picks one)", outputs.ws)
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
