"""``gesturecast bench latency FILE --json`` (or ``--device NAME``): the live engine in real time.

Measures end-to-end latency (audio capture → bytes handed to the bridges), per-stage compute,
real-time factor, deadline misses and audio skipped ahead, with the real VMC and WebSocket bridges on
loopback. The input is a recording at real-time pace, or a microphone (``--device``, for
``--seconds`` seconds), where capture times come from PortAudio's ADC timestamps; with no sound
card, ``python -m gesturecast.tools.bench.virtual_mic SPEECH -- gesturecast bench latency --device
pulse`` provides one. The first ``START_WINDOW_S`` seconds of frames are reported apart (``start``),
to show whether the run misses deadlines while it starts; ``--no-warm-up`` skips the engine's
warm-up, to measure what it saves. ``--sweep`` repeats the run for every ``--latency`` setting of the
model (and of each ``--sweep-models`` bundle; :mod:`gesturecast.tools.bench.timing.latency_sweep`);
``--sweep-steps`` repeats it for K ∈ {1, 2, 4, 8, 16} (and each ``--sweep-models`` bundle, e.g. bundles
trained with other look-aheads δa). Both write a Markdown table and a plot.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np

from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.vmc import VMC_DEFAULT_PORT, VmcBridge, VmcConfig
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.errors import UserError
from gesturecast.files import save_figure, write_text_atomic
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.sources import DEFAULT_CHUNK, AudioSource, MicConfig, MicSource, PacedFileSource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.run.engine import COMPUTE_STAGES, STAGE_MARGIN_USED, EngineReport, LiveEngine, Sink
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.latency import MS_PER_S
from gesturecast.settings import Settings
from gesturecast.tools.bench.timing.latency_sweep import latency_sweep
from gesturecast.tools.bench.timing.load import add_load_argument, competing_load

SWEEP_STEPS = (1, 2, 4, 8, 16)
PERCENTILES = ("p50", "p95", "p99", "max")
DEFAULT_DEVICE_SECONDS = 60.0  # how long --device records when --seconds is not given
START_WINDOW_S = 5.0  # frames captured in the first seconds are reported apart ("start" vs "after_start")
LATE_AFTER_S = 1.0 / 30.0  # a frame sent a whole frame period after its presentation time counts as late
LATE_INDICES_SHOWN = 20  # late frames listed by index (the rest are only counted)


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("latency", help="end-to-end latency of the live engine (file or microphone)")
    parser.add_argument("audio", type=Path, nargs="?", help="speech file replayed at real-time pace")
    parser.add_argument("--device", help="measure from this microphone (index or name substring) instead of a file")
    parser.add_argument("--seconds", type=float, help="use only the first N seconds of the file; with --device: "
                        f"record for N seconds (default {DEFAULT_DEVICE_SECONDS:.0f})")
    parser.add_argument("--no-warm-up", dest="warm_up", action="store_false",
                        help="open the source without warming the stages up first (to measure what that saves)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--sweep", action="store_true",
                        help="every --latency setting (and --sweep-models bundle): L, p95, misses, following; "
                             "table + plot")
    parser.add_argument("--sweep-steps", action="store_true", help="vary K (and --sweep-models bundles); table + plot")
    parser.add_argument("--sweep-models", type=Path, nargs="*", default=[], help="extra bundles for the sweeps")
    parser.add_argument("--out", type=Path, default=Path("out/bench"), help="folder for the sweep table and plot")
    parser.add_argument("--block-size", type=int, default=DEFAULT_CHUNK, help="samples per audio chunk (16 kHz)")
    parser.add_argument("--no-ladder", dest="ladder", action="store_false",
                        help="keep the degradation ladder off (the full work on every latent, late or not)")
    add_load_argument(parser)
    add_generation_arguments(parser)
    parser.set_defaults(func=run_bench_latency)


def run_bench_latency(args: argparse.Namespace) -> int:
    if (args.audio is None) == (args.device is None):
        raise UserError("give a speech FILE or --device NAME (one of them)")
    if args.device is not None and (args.sweep or args.sweep_steps):
        raise UserError("the sweeps run on a file; drop --device")
    with competing_load(args.load) as load:
        result = _measured(args)
    result["load"] = load
    sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
    return 0


def _measured(args: argparse.Namespace) -> dict:
    """The microphone run, the sweep asked, or one run on the file."""
    if args.device is not None:
        return measure(args, None)
    with tempfile.TemporaryDirectory() as scratch:
        audio = _trimmed(args.audio, args.seconds, Path(scratch))
        if args.sweep:
            return latency_sweep(args, audio, measure_with_frames)
        if args.sweep_steps:
            rows = _sweep(args, audio)
            _write_sweep(rows, args.out)
            return {"sweep": rows, "table": str(args.out / "latency_sweep.md"),
                    "plot": str(args.out / "latency_sweep.png")}
        return measure(args, audio)


def _trimmed(path: Path, seconds: float | None, scratch: Path) -> Path:
    if seconds is None:
        return path
    import soundfile

    audio = load_audio(path)[: int(seconds * SAMPLE_RATE)]
    trimmed = scratch / "trimmed.wav"
    soundfile.write(trimmed, audio, SAMPLE_RATE, subtype="FLOAT")
    return trimmed


class ReleaseLog:
    """A sink in front of the bridges that records, per frame, its capture time and how late it was sent."""

    def __init__(self, sink: Sink, clock: Clock, keep_frames: bool = False) -> None:
        self.sink = sink
        self.clock = clock
        self.rows: list[tuple[float, float]] = []  # (capture time, lateness s) per frame
        self.frames: list[PoseFrame] | None = [] if keep_frames else None  # the released frames (sweeps only)

    def send(self, frame: PoseFrame) -> None:
        self.rows.append((frame.capture_time, self.clock.now() - frame.presentation_time))
        if self.frames is not None:
            self.frames.append(frame)
        self.sink(frame)

    def windows(self) -> dict:
        """Late frames in the first START_WINDOW_S seconds of capture and after them."""
        if not self.rows:
            return {}
        rows = np.array(self.rows)  # (T, 2): capture time, lateness
        in_start = rows[:, 0] < rows[0, 0] + START_WINDOW_S  # (T,)
        return {"start": lateness_summary(rows[in_start, 1]), "after_start": lateness_summary(rows[~in_start, 1]),
                "start_window_s": START_WINDOW_S, "late_after_ms": LATE_AFTER_S * MS_PER_S}


def lateness_summary(lateness_s: np.ndarray) -> dict:
    """(n,) seconds late per frame → frames, late frames (indices) and the worst lateness in ms."""
    late = np.flatnonzero(lateness_s > LATE_AFTER_S)
    return {"frames": int(lateness_s.shape[0]), "late_frames": int(late.shape[0]),
            "late_frame_indices": [int(i) for i in late[:LATE_INDICES_SHOWN]],
            "max_lateness_ms": float(lateness_s.max() * MS_PER_S) if lateness_s.size else None}


def open_bench_source(args: argparse.Namespace, audio: Path | None, clock: Clock
                      ) -> tuple[AudioSource, Callable[[], None] | None]:
    """The file at real-time pace; or the microphone, and what starts the timer thread that closes it after
    --seconds (started once the engine is warm, as the microphone opens: a warm-up longer than --seconds must not
    use the time up)."""
    if audio is not None:
        return PacedFileSource(audio, args.block_size, clock), None
    source = MicSource(MicConfig(device=args.device, block_size=args.block_size), clock)
    timer = threading.Timer(args.seconds or DEFAULT_DEVICE_SECONDS, source.close)
    timer.daemon = True
    return source, timer.start


def measure(args: argparse.Namespace, audio: Path | None, settings: Settings | None = None) -> dict:
    """One real-time run with the real bridges on loopback (``settings``: default, the flags'); returns the
    benchmark's JSON object."""
    return measure_with_frames(args, audio, settings=settings)[0]


def measure_with_frames(args: argparse.Namespace, audio: Path | None, keep_frames: bool = False,
                        settings: Settings | None = None) -> tuple[dict, list[PoseFrame] | None]:
    """:func:`measure`, plus the frames it released when ``keep_frames``."""
    settings = settings_from_args(args) if settings is None else settings
    clock = MonotonicClock()
    session = build_session(settings, clock)
    viewer = WebSocketBridge(WebSocketConfig(port=0, clock=clock.now)).start()
    vmc = VmcConfig(port=VMC_DEFAULT_PORT, viseme_names=session.viseme_names)  # blend shapes per --lipsync
    outputs = BridgeFanout([VmcBridge(vmc), viewer])
    log = ReleaseLog(outputs.send, clock, keep_frames)
    try:
        source, on_open = open_bench_source(args, audio, clock)
        report = LiveEngine(session, source, log.send, clock, warm=args.warm_up, on_warm=on_open,
                            adapt=args.ladder).run()
    finally:
        outputs.close()
    return {**benchmark_json(report, args, settings, session.generator.guidance), **log.windows()}, log.frames


def benchmark_json(report: EngineReport, args: argparse.Namespace, settings: Settings, guidance: float) -> dict:
    stages = report.latency
    end_to_end = stages.get("end_to_end", {})
    return {
        "latency_budget_ms": report.budget["latency_budget_ms"],
        "end_to_end_ms": {p: end_to_end.get(p) for p in PERCENTILES},
        "stages_ms": {name: {p: stages[name][p] for p in PERCENTILES} for name in COMPUTE_STAGES if name in stages},
        "margin_used_ms": {p: stages.get(STAGE_MARGIN_USED, {}).get(p) for p in PERCENTILES},
        "rtf": report.rtf,
        "deadline_misses": report.scheduler.get("deadline_misses", 0),
        "degradation": report.degradation,
        "audio_skipped_samples": report.audio["skipped_samples"],
        "audio_skip_aheads": report.audio["skip_aheads"],
        "device_overflows": report.audio["device_overflows"],
        "untimed_audio_blocks": report.audio["untimed_blocks"],
        "warm_up_ms": report.warm_up_s * MS_PER_S,
        "frames": report.frames,
        "audio_seconds": report.audio_seconds,
        "root": report.root,
        "settings": {
            "sampler": settings.sampler,
            "steps": settings.steps if settings.sampler == "ddim" else None,
            "latency": settings.latency,
            "lookahead_frames": report.budget.get("lookahead_frames"),
            "compute_margin_ms": report.budget.get("compute_margin_ms"),
            "guidance": guidance,
            "audio_guidance": settings.audio_guidance,
            "threads": settings.threads,
            "block_size": args.block_size,
            "model": str(settings.model),
            "source": f"device {args.device}" if args.device is not None else "file",
        },
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
    }


def _sweep(args: argparse.Namespace, audio: Path) -> list[dict]:
    rows = []
    for model in [args.model, *args.sweep_models]:
        for steps in SWEEP_STEPS:
            result = measure(args, audio, settings_from_args(args, model=model, steps=steps, sampler="ddim"))
            rows.append({
                "model": str(model),
                "lookahead_frames": result["settings"]["lookahead_frames"],
                "steps": steps,
                "rtf": result["rtf"],
                "denoiser_p95_ms": result["stages_ms"]["denoiser"]["p95"],
                "end_to_end_p95_ms": result["end_to_end_ms"]["p95"],
                "latency_budget_ms": result["latency_budget_ms"],
                "deadline_misses": result["deadline_misses"],
            })
    return rows


def _write_sweep(rows: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    header = (
        "| δa | K | rtf | denoiser p95 ms | end-to-end p95 ms | L ms | deadline misses |\n"
        "|---|---|---|---|---|---|---|\n"
    )
    lines = [
        f"| {r['lookahead_frames']} | {r['steps']} | {r['rtf']:.4f} | {r['denoiser_p95_ms']:.2f} | "
        f"{r['end_to_end_p95_ms']:.1f} | {r['latency_budget_ms']:.0f} | {r['deadline_misses']} |"
        for r in rows
    ]
    write_text_atomic(out / "latency_sweep.md", header + "\n".join(lines) + "\n")
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for lookahead in sorted({r["lookahead_frames"] for r in rows}):
        subset = [r for r in rows if r["lookahead_frames"] == lookahead]
        steps = [r["steps"] for r in subset]
        left.plot(steps, [r["rtf"] for r in subset], "o-", label=f"δa = {lookahead}")
        right.plot(steps, [r["end_to_end_p95_ms"] for r in subset], "o-", label=f"δa = {lookahead}")
        right.axhline(subset[0]["latency_budget_ms"], linestyle=":", color="grey")
    left.set(xscale="log", xlabel="DDIM steps K", ylabel="real-time factor", title="compute per audio second")
    right.set(xscale="log", xlabel="DDIM steps K", ylabel="ms", title="end-to-end p95 (dotted: budget L)")
    for axis in (left, right):
        axis.set_xticks(SWEEP_STEPS, [str(k) for k in SWEEP_STEPS])
        axis.legend()
        axis.grid(alpha=0.3)
    figure.tight_layout()
    save_figure(figure, out / "latency_sweep.png", dpi=110)
    plt.close(figure)
