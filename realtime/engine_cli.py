"""``gesturecast live`` and ``gesturecast generate``: one session code path for both (and for ``demo``).

The engine (the session, onnxruntime, the offline run, the batch runner) is imported when a command runs, not when
its parser is built: ``gesturecast live --help`` answers without it.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gesturecast import stop_signals
from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.osc_in import (
    GESTURE_ADDRESS,
    INTENSITY_ADDRESS,
    PAUSE_ADDRESS,
    OscControlListener,
    OscInConfig,
)
from gesturecast.bridges.output_settings import parse_host_port
from gesturecast.bridges.vrma import FOLDED, VRMA_BONES
from gesturecast.bridges.ws_access import is_loopback
from gesturecast.errors import INTERRUPTED_EXIT, UserError
from gesturecast.files import check_distinct
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.dsp import frame_boundary
from gesturecast.models.audio.files import SAMPLE_RATE, AudioFileReader
from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.source_flags import add_source_arguments, open_source
from gesturecast.realtime.cli_flags import (
    add_batch_arguments,
    add_generation_arguments,
    add_output_arguments,
    add_transcript_argument,
    outputs_from_args,
    server_token,
    settings_from_args,
)
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.scheduler import STAGE_END_TO_END, SchedulerConfig
from gesturecast.realtime.timing.status import StatusLine
from gesturecast.settings import DEFAULT_GESTURES_DIR

if TYPE_CHECKING:
    from gesturecast.realtime.gestures.transcripts import Transcript
    from gesturecast.realtime.pose.session import GestureSession
    from gesturecast.realtime.run.engine import EngineReport

logger = logging.getLogger(__name__)


def register(subparsers: argparse._SubParsersAction) -> None:
    live = subparsers.add_parser("live", help="speech in (microphone or --input FILE), gestures out, live")
    add_source_arguments(live)
    add_generation_arguments(live)
    add_transcript_argument(live)
    add_output_arguments(live)
    live.add_argument("--osc-in", metavar="[HOST:]PORT", help=f"fire gestures ({GESTURE_ADDRESS} NAME), set the "
                      f"gesture size ({INTENSITY_ADDRESS} 0..2) or pause ({PAUSE_ADDRESS} 1, 0 resumes) by OSC from "
                      "a Stream Deck, TouchOSC, VNyan or a game engine; loopback unless HOST is given (then the "
                      "token is the message's second string; docs/gestures.md)")
    live.set_defaults(func=run_live)

    generate = subparsers.add_parser("generate", help="offline: audio file → BVH (same session code as live); "
                                     "--batch: a folder or CSV of files → a folder of BVHs")
    generate.add_argument("audio", type=Path, nargs="?", help="speech file (any format soundfile reads)")
    generate.add_argument("-o", "--output", type=Path, required=True,
                          help="file to write: .bvh (BVH), .vrma (VRM Animation) or .json (the pose stream); with "
                          "--batch: the output folder")
    generate.add_argument("--json", type=Path, metavar="FILE", help="also write the pose stream as JSON")
    generate.add_argument("--vrma", type=Path, metavar="FILE", help="also write the motion as VRM Animation (.vrma)")
    generate.add_argument("--vrma-bones", choices=VRMA_BONES, default=FOLDED,
                          help="a .vrma's torso: 'folded' (default) turns the chest by chest·upperChest and leaves the "
                          "upper chest still, so players that skip bones an avatar lacks (three-vrm-animation on an "
                          "avatar without an upper chest, like the bundled one) keep the upper body's pose; 'full' "
                          "writes every bone as generated (exact on avatars with an upper chest)")
    add_batch_arguments(generate)
    add_generation_arguments(generate)
    add_transcript_argument(generate)
    generate.set_defaults(func=run_generate)


def run_live(args: argparse.Namespace) -> int:
    from gesturecast.realtime.gestures.transcripts import transcript_beside, transcript_file
    from gesturecast.realtime.run.engine import LiveEngine
    from gesturecast.realtime.run.engine_setup import build_outputs, build_session

    check_distinct([("--input", args.input)], [("--bvh", args.bvh)])
    settings, chosen = settings_from_args(args), outputs_from_args(args)
    if not chosen.any:
        raise UserError("no output chosen: add --vmc HOST:PORT, --osc HOST:PORT, --ws PORT and/or --bvh FILE")
    if args.transcript is not None and not args.input:
        raise UserError("--transcript gives the words of an --input file (a microphone's words come as they are "
                        "spoken: send them as a words message)")
    transcript = transcript_file(args.transcript or transcript_beside(args.input), settings, args.input)
    osc_in = osc_in_address(args.osc_in)  # checked before any output file is opened
    clock = MonotonicClock()
    session = build_session(settings, clock)
    session.gestures.start_worker()  # the words' work never delays a frame
    if args.input:
        check_input_length(args.input)
    source = open_source(args, clock)  # checks the input before any output file is opened
    try:
        outputs = build_outputs(chosen, settings, session, clock)
    except BaseException:
        source.close()
        raise
    gestures_in = None
    try:
        gestures_in = osc_listener(args, osc_in, session)
        sys.stdout.write(session.budget.describe() + "\n")
        engine = LiveEngine(session, source, outputs.send, clock, scheduler_config(args), StatusLine(clock),
                            on_warm=lambda: start_stream_inputs(session, transcript, gestures_in))
        report = engine.run()
    finally:
        source.close()  # already closed after a run; not yet opened when the OSC port was refused
        if gestures_in is not None:
            gestures_in.close()
        outputs.close()
        session.gestures.stop_worker()
    report.outputs = outputs.counters()
    if gestures_in is not None:  # its drops (malformed, wrong token, refused...) in the summary and the report
        report.outputs["osc_in"] = gestures_in.dropped()
    sys.stdout.write(summary_line(report) + "\n")
    if session.gestures.alignments:
        sys.stdout.write(f"sentences without word times: {session.gestures.alignments.describe()}\n")
    raise_output_errors(outputs)
    return exit_status(report)


def osc_in_address(value: str | None) -> tuple[str, int] | None:
    """``--osc-in [HOST:]PORT`` → (host, port), None without it; a one-line error quoting what was typed."""
    if value is None:
        return None
    try:
        return parse_host_port(value if ":" in value else f":{value}", "--osc-in")
    except UserError:
        raise UserError(f"--osc-in wants a port (1 to 65535) or HOST:PORT, e.g. 9001 or 0.0.0.0:9001; got {value!r}"
                        ) from None


def osc_listener(args: argparse.Namespace, address: tuple[str, int] | None,
                 session: GestureSession) -> OscControlListener | None:
    """The ``--osc-in`` port at ``address``, bound but not yet listening (None without it): its gesture messages go
    through the control checks to the session."""
    if address is None:
        return None
    host, port = address
    token = server_token(args) if not is_loopback(host) else None
    return OscControlListener(OscInConfig(host, port, token), session.controls.submit)


def start_stream_inputs(session: GestureSession, transcript: Transcript,
                        gestures_in: OscControlListener | None) -> None:
    """Once the stages are warm and the stream starts: the transcript's cues, then the OSC gesture port."""
    transcript.cue(session.gestures)
    if gestures_in is not None:
        gestures_in.start()


def check_input_length(path: Path) -> None:
    """Refuse, before any output opens, an input file too short to complete one motion frame (no pose at all)."""
    first_frame_samples = frame_boundary(1, SAMPLE_RATE, int(MOTION_FPS))
    if round(AudioFileReader(path).duration_s * SAMPLE_RATE) < first_frame_samples:
        raise UserError(f"{path} is shorter than one motion frame (1/{MOTION_FPS:g} s)")


def raise_output_errors(outputs: BridgeFanout) -> None:
    """After the summary: an output that could not be finished (e.g. a BVH on a full disk) fails the run."""
    if outputs.close_errors:
        raise UserError("; ".join(outputs.close_errors))


def run_generate(args: argparse.Namespace) -> int:
    from gesturecast.realtime.gestures.transcripts import transcript_beside, transcript_file
    from gesturecast.realtime.jobs.batch_cli import run_batch
    from gesturecast.realtime.run.engine_setup import build_session
    from gesturecast.realtime.run.offline_generate import body_only, generate_to_files

    if args.batch is not None:
        if args.vrma_bones != FOLDED:
            raise UserError("--vrma-bones full is for one file; a batch writes its .vrma files folded")
        return run_batch(args)
    if args.audio is None:
        raise UserError("name an audio file, or a folder / CSV with --batch")
    check_distinct([("audio", args.audio)], [("-o", args.output), ("--json", args.json), ("--vrma", args.vrma)])
    motion_paths, json_path = output_files(args)
    settings = settings_from_args(args)
    transcript = transcript_file(args.transcript or transcript_beside(args.audio), settings, args.audio)
    if not transcript and settings.gestures == DEFAULT_GESTURES_DIR:  # no words, no gesture: the bundled lexicon is
        settings = dataclasses.replace(settings, gestures=None)  # not encoded (0.1 s); a user's folder is still checked
    session = build_session(body_only(settings, motion_paths, json_path), MonotonicClock())
    transcript.cue(session.gestures)
    report = generate_to_files(session, args.audio, motion_paths, json_path, args.vrma_bones)
    process_cpu = time.process_time()  # the whole command: start-up, model, generation, files
    logger.info("process CPU %.2f s for %.1f s of audio: %.3f s per second", process_cpu, report.audio_seconds,
                process_cpu / report.audio_seconds)
    return 0


def output_files(args: argparse.Namespace) -> tuple[list[Path], Path | None]:
    """``generate``'s motion files (-o as BVH or .vrma, --vrma) and pose-stream JSON (-o as .json, or --json)."""
    from gesturecast.realtime.run.offline_generate import JSON_SUFFIX, OUTPUT_SUFFIXES, VRMA_SUFFIX, check_motion_path

    output = check_motion_path(args.output, "-o", OUTPUT_SUFFIXES)
    if output.suffix.lower() == JSON_SUFFIX and args.json is not None:
        raise UserError(f"-o {output} already writes the pose stream as JSON; drop --json {args.json}")
    motion_paths = [] if output.suffix.lower() == JSON_SUFFIX else [output]
    if args.vrma is not None:
        motion_paths.append(check_motion_path(args.vrma, "--vrma", (VRMA_SUFFIX,)))
    return motion_paths, output if output.suffix.lower() == JSON_SUFFIX else args.json


def scheduler_config(args: argparse.Namespace) -> SchedulerConfig:
    """Release at presentation times, or at once for a file read as fast as possible (``--pace fast``)."""
    unpaced = bool(args.input) and args.pace == "fast"
    return SchedulerConfig(output_fps=float(args.fps), paced=not unpaced)


def exit_status(report: EngineReport) -> int:
    """0 when the source ran out, the shell's Ctrl-C status when the run was interrupted."""
    return INTERRUPTED_EXIT if report.interrupted else 0


def summary_line(report: EngineReport) -> str:
    """The final one-line summary; counters that are zero in a healthy run appear only when non-zero."""
    e2e = report.latency.get(STAGE_END_TO_END)
    sched = report.scheduler
    latency = (f"end-to-end p50 {e2e['p50']:.0f} p95 {e2e['p95']:.0f} p99 {e2e['p99']:.0f} ms" if e2e
               else "end-to-end n/a (unpaced)")
    prefix = f"stopped by {stop_signals.stopped_by()}: " if report.interrupted else ""
    parts = [
        f"{prefix}{report.frames} frames from {report.audio_seconds:.1f} s of audio",
        f"rtf {report.rtf:.3f}",
        f"{latency} (L {report.budget['latency_budget_ms']:.0f} ms)",
        f"deadline misses {sched.get('deadline_misses', 0)}",
        f"late releases {sched.get('late_releases', 0)}",
        f"audio skipped {report.audio['skipped_samples']}",
    ]
    if report.root:
        parts.append(root_summary(report.root))
    if report.nonfinite_poses:
        parts.append(f"non-finite poses held {report.nonfinite_poses}")
    if any(report.gesture_cues.values()):
        parts.append("gesture cues " + ", ".join(f"{status} {n}" for status, n in report.gesture_cues.items() if n))
    dropped = {name: n for bridge in report.outputs.values() for name, n in bridge.items() if n}
    parts.extend(f"{name.replace('_', ' ')} {n}" for name, n in dropped.items())
    return " | ".join(parts)


def root_summary(root: dict) -> str:
    """Where the avatar went: hips distance from the start (largest, and start to end) and largest turn."""
    return (f"root max {root['max_distance_m']:.2f} m, net {root['net_travel_m']:.2f} m, "
            f"facing max {root['max_facing_deg']:.0f}°")


def frames_to_motion(frames: list[PoseFrame]) -> SkeletonMotion:
    rotations = np.stack([f.rotations for f in frames])  # (T, J, 4)
    roots = np.stack([f.root_position for f in frames])  # (T, 3)
    return SkeletonMotion(rotations, roots, MOTION_FPS, CANONICAL_WITH_HANDS)
