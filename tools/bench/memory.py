"""``gesturecast bench memory FILE --hours 1 --json --plot rss.png``: is one session's memory flat over hours?

Runs one :class:`GestureSession` on ``--hours`` of audio (the file tiled end to end) as fast as possible
and samples the process's resident set size (``VmRSS`` from ``/proc/self/status``; no psutil) every
``--every`` seconds of stream time. Prints start / end / max RSS and the least-squares slope in MB per
hour of stream (fitted after ``--warmup`` seconds, when one-time allocations are done), and plots RSS
against stream time. Frames are counted and dropped, so the benchmark itself holds nothing per frame.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import save_figure
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.run.engine import compute_seconds
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock

PROC_STATUS = Path("/proc/self/status")
KIB_PER_MIB = 1024.0
SECONDS_PER_HOUR = 3600.0
CHUNK_SAMPLES = 16000  # 1 s per push: the session is chunk-size invariant, larger chunks cost less Python
DEFAULT_EVERY_S = 60.0
DEFAULT_WARMUP_S = 300.0


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("memory", help="RSS of one session over hours of audio (JSON + plot)")
    parser.add_argument("audio", type=Path, help="speech file, tiled to the requested length")
    parser.add_argument("--hours", type=float, default=1.0, help="stream length in hours")
    parser.add_argument("--every", type=float, default=DEFAULT_EVERY_S, help="seconds of stream between samples")
    parser.add_argument("--warmup", type=float, default=DEFAULT_WARMUP_S, help="stream seconds left out of the slope")
    parser.add_argument("--json", action="store_true", help="print one JSON object on one line")
    parser.add_argument("--plot", type=Path, help="write RSS vs stream time here (PNG)")
    add_generation_arguments(parser)
    parser.set_defaults(func=run_bench_memory)


def rss_mb(status: Path = PROC_STATUS) -> float:
    """Resident set size of this process in MiB, from the kernel's ``VmRSS`` line."""
    if not status.is_file():
        raise UserError(f"no {status}: this benchmark needs Linux /proc")
    for line in status.read_text(encoding="utf-8").splitlines():
        if line.startswith("VmRSS:"):
            return float(line.split()[1]) / KIB_PER_MIB
    raise UserError(f"no VmRSS line in {status}; this benchmark needs Linux /proc")


def tiled_chunks(audio: np.ndarray, total_samples: int, chunk: int = CHUNK_SAMPLES) -> Iterator[AudioChunk]:
    """``audio`` repeated end to end for ``total_samples`` samples, as chunks with stream-time capture times."""
    if audio.size == 0:
        raise UserError("the audio file is empty")
    for start in range(0, total_samples, chunk):
        index = np.arange(start, min(start + chunk, total_samples)) % audio.size
        yield AudioChunk(audio[index], start, start / SAMPLE_RATE)


def slope_per_hour(times_s: np.ndarray, values: np.ndarray, warmup_s: float) -> float | None:
    """Least-squares slope (value units per hour) over samples at or after ``warmup_s``; None if < 2."""
    keep = times_s >= warmup_s
    if keep.sum() < 2:
        return None
    return float(np.polyfit(times_s[keep] / SECONDS_PER_HOUR, values[keep], 1)[0])


def run_bench_memory(args: argparse.Namespace) -> int:
    session = build_session(settings_from_args(args), MonotonicClock())
    total = int(args.hours * SECONDS_PER_HOUR * SAMPLE_RATE)
    every = max(int(args.every * SAMPLE_RATE), 1)
    times, rss = [0.0], [rss_mb()]
    frames, next_sample, started = 0, every, time.monotonic()
    for chunk in tiled_chunks(load_audio(args.audio), total):
        frames += len(session.push(chunk))
        if chunk.start_sample + len(chunk.samples) >= next_sample:
            times.append((chunk.start_sample + len(chunk.samples)) / SAMPLE_RATE)
            rss.append(rss_mb())
            next_sample += every
    frames += len(session.finish())
    wall = time.monotonic() - started
    result = memory_summary(np.array(times), np.array(rss), args.warmup)
    result |= {"frames": frames, "wall_seconds": wall, "rtf": compute_seconds(session) / (total / SAMPLE_RATE),
               "settings": {"model": str(args.model), "steps": args.steps, "guidance": session.generator.guidance}}
    if args.plot is not None:
        plot_trace(np.array(times), np.array(rss), args.plot, result)
        result["plot"] = str(args.plot)
    sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
    return 0


def memory_summary(times_s: np.ndarray, rss: np.ndarray, warmup_s: float) -> dict:
    after = rss[times_s >= warmup_s]
    return {
        "stream_hours": float(times_s[-1] / SECONDS_PER_HOUR),
        "samples": int(times_s.size),
        "rss_mb": {
            "start": float(rss[0]),
            "after_warmup": float(after[0]) if after.size else None,
            "end": float(rss[-1]),
            "max": float(rss.max()),
        },
        "slope_mb_per_hour": slope_per_hour(times_s, rss, warmup_s),
        "warmup_seconds": warmup_s,
        "trace": {"stream_seconds": times_s.round(1).tolist(), "rss_mb": rss.round(2).tolist()},
    }


def plot_trace(times_s: np.ndarray, rss: np.ndarray, path: Path, result: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(8, 4))
    axis.plot(times_s / 60.0, rss, ".-")
    axis.axvline(result["warmup_seconds"] / 60.0, linestyle=":", color="grey", label="end of warm-up")
    slope = result["slope_mb_per_hour"]
    slope_text = "n/a" if slope is None else f"{slope:+.2f} MB/h"
    axis.set(xlabel="stream time (minutes)", ylabel="RSS (MiB)",
             title=f"one session, {result['stream_hours']:.2f} h of audio: slope after warm-up {slope_text}")
    axis.set_ylim(0, rss.max() * 1.2)
    axis.grid(alpha=0.3)
    axis.legend()
    figure.tight_layout()
    save_figure(figure, path, dpi=110)
    plt.close(figure)
