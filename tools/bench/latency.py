"""``gesturecast bench latency FILE --json``: the live engine on a recording at real-time pace.

Measures end-to-end latency (audio capture → bytes handed to the bridges), per-stage compute,
real-time factor, deadline misses and audio drops, with the real VMC and WebSocket bridges on
loopback. ``--sweep`` repeats the run for K ∈ {1, 2, 4, 8, 16} (and for each ``--model`` given,
e.g. bundles trained with other look-aheads δa) and writes a Markdown table and a plot.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
from pathlib import Path

from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.vmc import VMC_DEFAULT_PORT, VmcBridge, VmcConfig
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.files import save_figure, write_text_atomic
from gesturecast.realtime.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.sources import DEFAULT_CHUNK, PacedFileSource
from gesturecast.realtime.engine import EngineReport, LiveEngine
from gesturecast.realtime.engine_setup import add_generation_arguments, build_session
from gesturecast.realtime.timing.clock import MonotonicClock

SWEEP_STEPS = (1, 2, 4, 8, 16)
PERCENTILES = ("p50", "p95", "p99", "max")
STAGES = ("features", "denoiser", "decoder", "bridge")


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("latency", help="end-to-end latency of the live engine on a file")
    parser.add_argument("audio", type=Path, help="speech file replayed at real-time pace")
    parser.add_argument("--seconds", type=float, help="use only the first N seconds of the file")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--sweep", action="store_true", help="vary K (and --model bundles) and write table + plot")
    parser.add_argument("--sweep-models", type=Path, nargs="*", default=[], help="extra bundles for the δa sweep")
    parser.add_argument("--out", type=Path, default=Path("out/bench"), help="folder for the sweep table and plot")
    parser.add_argument("--block-size", type=int, default=DEFAULT_CHUNK, help="samples per audio chunk (16 kHz)")
    add_generation_arguments(parser)
    parser.set_defaults(func=run_bench_latency)


def run_bench_latency(args: argparse.Namespace) -> int:
    with tempfile.TemporaryDirectory() as scratch:
        audio = _trimmed(args.audio, args.seconds, Path(scratch))
        if args.sweep:
            rows = _sweep(args, audio)
            _write_sweep(rows, args.out)
            result = {"sweep": rows, "table": str(args.out / "latency_sweep.md"),
                      "plot": str(args.out / "latency_sweep.png")}
        else:
            result = measure(args, audio)
    sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
    return 0


def _trimmed(path: Path, seconds: float | None, scratch: Path) -> Path:
    if seconds is None:
        return path
    import soundfile

    audio = load_audio(path)[: int(seconds * SAMPLE_RATE)]
    trimmed = scratch / "trimmed.wav"
    soundfile.write(trimmed, audio, SAMPLE_RATE, subtype="FLOAT")
    return trimmed


def measure(args: argparse.Namespace, audio: Path) -> dict:
    """One real-time run with the real bridges on loopback; returns the benchmark's JSON object."""
    clock = MonotonicClock()
    session = build_session(args, clock)
    viewer = WebSocketBridge(WebSocketConfig(port=0, clock=clock.now)).start()
    outputs = BridgeFanout([VmcBridge(VmcConfig(port=VMC_DEFAULT_PORT)), viewer])
    try:
        report = LiveEngine(session, PacedFileSource(audio, args.block_size, clock), outputs.send, clock).run()
    finally:
        outputs.close()
    return benchmark_json(report, args, session.generator.guidance)


def benchmark_json(report: EngineReport, args: argparse.Namespace, guidance: float) -> dict:
    stages = report.latency
    end_to_end = stages.get("end_to_end", {})
    return {
        "latency_budget_ms": report.budget["latency_budget_ms"],
        "end_to_end_ms": {p: end_to_end.get(p) for p in PERCENTILES},
        "stages_ms": {name: {p: stages[name][p] for p in ("p50", "p95")} for name in STAGES if name in stages},
        "rtf": report.rtf,
        "deadline_misses": report.scheduler.get("deadline_misses", 0),
        "audio_drops": report.audio["dropped_samples"],
        "frames": report.frames,
        "audio_seconds": report.audio_seconds,
        "settings": {
            "sampler": args.sampler,
            "steps": args.steps if args.sampler == "ddim" else None,
            "lookahead_frames": report.budget.get("lookahead_frames"),
            "guidance": guidance,
            "audio_guidance": args.audio_guidance,
            "threads": args.threads,
            "block_size": args.block_size,
            "model": str(args.model),
        },
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
    }


def _sweep(args: argparse.Namespace, audio: Path) -> list[dict]:
    rows = []
    for model in [args.model, *args.sweep_models]:
        for steps in SWEEP_STEPS:
            run_args = argparse.Namespace(**{**vars(args), "model": model, "steps": steps, "sampler": "ddim"})
            result = measure(run_args, audio)
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
