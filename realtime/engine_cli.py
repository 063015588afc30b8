"""``gesturecast live``, ``gesturecast generate`` and ``gesturecast demo``: one session code path for all three."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

import numpy as np

from gesturecast.bridges.vmc import VMC_DEFAULT_PORT
from gesturecast.bridges.websocket_server import WS_DEFAULT_PORT
from gesturecast.errors import UserError
from gesturecast.models.motion import Motion
from gesturecast.models.retarget import motion_to_bvh
from gesturecast.models.skeleton import CANONICAL
from gesturecast.realtime.audio_cli import add_source_arguments, open_source
from gesturecast.realtime.clock import MonotonicClock
from gesturecast.realtime.engine import EngineReport, LiveEngine, run_offline
from gesturecast.realtime.engine_setup import (
    add_generation_arguments,
    add_output_arguments,
    build_outputs,
    build_session,
)
from gesturecast.realtime.frames import PoseFrame
from gesturecast.realtime.scheduler import SchedulerConfig
from gesturecast.realtime.sources import FastFileSource
from gesturecast.realtime.status import StatusLine

logger = logging.getLogger(__name__)

SAMPLE_AUDIO = Path(__file__).resolve().parents[1] / "gesturecast" / "samples" / "sample_speech.wav"
DEMO_OUT = Path("out/demo")


def register(subparsers: argparse._SubParsersAction) -> None:
    live = subparsers.add_parser("live", help="speech in (microphone or --input FILE), gestures out, live")
    add_source_arguments(live)
    add_generation_arguments(live)
    add_output_arguments(live)
    live.set_defaults(func=run_live)

    generate = subparsers.add_parser("generate", help="offline: audio file → BVH (same session code as live)")
    generate.add_argument("audio", type=Path, help="speech file (any format soundfile reads)")
    generate.add_argument("-o", "--output", type=Path, required=True, help="BVH file to write")
    generate.add_argument("--json", type=Path, metavar="FILE", help="also write the pose stream as JSON")
    add_generation_arguments(generate)
    generate.set_defaults(func=run_generate)

    demo = subparsers.add_parser("demo", help="the bundled sample through the live engine (no arguments needed)")
    add_generation_arguments(demo)
    demo.add_argument("--out", type=Path, default=DEMO_OUT, help="folder for the BVH, preview and latency JSON")
    demo.set_defaults(func=run_demo)


def run_live(args: argparse.Namespace) -> int:
    clock = MonotonicClock()
    session = build_session(args, clock)
    outputs = build_outputs(args, session, clock)
    if not outputs.bridges:
        raise UserError("no output chosen: add --vmc HOST:PORT, --osc HOST:PORT, --ws PORT and/or --bvh FILE")
    sys.stdout.write(session.budget.describe() + "\n")
    source = open_source(args, clock)
    engine = LiveEngine(session, source, outputs.send, clock, SchedulerConfig(output_fps=float(args.fps)),
                        StatusLine(clock))
    try:
        report = engine.run()
    except KeyboardInterrupt:
        engine.stop()
        return 130
    finally:
        outputs.close()
    sys.stdout.write(summary_line(report) + "\n")
    return 0


def run_generate(args: argparse.Namespace) -> int:
    session = build_session(args, MonotonicClock())
    frames, report = run_offline(session, FastFileSource(args.audio))
    if not frames:
        raise UserError(f"{args.audio} is shorter than one motion frame (1/30 s)")
    motion_to_bvh(frames_to_motion(frames), args.output)
    if args.json is not None:
        write_pose_json(frames, args.json)
    logger.info("wrote %d frames (%.1f s) to %s; rtf %.3f", len(frames), len(frames) / 30, args.output, report.rtf)
    return 0


def run_demo(args: argparse.Namespace) -> int:
    """Bundled sample at real-time pace → VMC on 127.0.0.1:39539 + WebSocket viewer + BVH + rendered preview."""
    args.input, args.pace, args.block_size = str(SAMPLE_AUDIO), "realtime", 512
    args.vmc, args.osc, args.osc_frame = f"127.0.0.1:{VMC_DEFAULT_PORT}", None, "unity"
    args.ws, args.host, args.token, args.fps = WS_DEFAULT_PORT, "127.0.0.1", None, 30
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
    from gesturecast.models.retarget import load_motion_file
    from gesturecast.tools.render import render_positions

    motion = load_motion_file(args.bvh)
    preview = render_positions(motion.positions(), motion.skeleton.parents, args.out / "demo.gif",
                               fps=motion.fps, title=f"gesturecast demo - style {args.style}",  # ASCII font
                               names=motion.skeleton.names)
    (args.out / "latency.json").write_text(json.dumps(report.to_dict(), indent=2) + "\n")
    sys.stdout.write(summary_line(report) + "\n")
    sys.stdout.write(f"wrote {args.bvh}, {preview} and {args.out / 'latency.json'}\n")


def summary_line(report: EngineReport) -> str:
    e2e = report.latency.get("end_to_end", {})
    sched = report.scheduler
    return (
        f"{report.frames} frames from {report.audio_seconds:.1f} s of audio | rtf {report.rtf:.3f} | "
        f"end-to-end p50 {e2e.get('p50', float('nan')):.0f} p95 {e2e.get('p95', float('nan')):.0f} "
        f"p99 {e2e.get('p99', float('nan')):.0f} ms (L {report.budget['latency_budget_ms']:.0f} ms) | "
        f"deadline misses {sched.get('deadline_misses', 0)} | audio drops {report.audio['dropped_samples']}"
    )


def frames_to_motion(frames: list[PoseFrame]) -> Motion:
    rotations = np.stack([f.rotations for f in frames])  # (T, J, 4)
    roots = np.stack([f.root_position for f in frames])  # (T, 3)
    return Motion(rotations, roots, 30.0, CANONICAL)


def write_pose_json(frames: list[PoseFrame], path: Path) -> None:
    """The pose stream as JSON: bone names once, then per frame seq, times, root and XYZW quaternions."""
    payload = {
        "bones": list(CANONICAL.names),
        "fps": 30,
        "frames": [
            {
                "seq": f.seq,
                "capture_time": f.capture_time,
                "root": [float(v) for v in f.root_position],
                "rotations": np.round(f.rotations, 7).tolist(),
                "speaking": f.speaking,
            }
            for f in frames
        ],
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(payload) + "\n")
