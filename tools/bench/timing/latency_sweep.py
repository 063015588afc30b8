"""``gesturecast bench latency FILE --sweep``: every ``--latency`` setting of every model, in real time.

For each model (``--model`` and each ``--sweep-models`` bundle) and each setting (low, balanced,
quality; docs/latency.md "Latency settings"): L, end-to-end p50 / p95 / p99, deadline misses, late
frames (sent more than a frame period, 33 ms, after their presentation time), the real-time
factor, and the speech-following score of the motion the run released for the file (energy–speed
correlation, :mod:`gesturecast.models.evaluation.speech_following`, the metric of ``bench
following``; one file and one seed, so read differences below ~0.05 as noise). A setting the model
cannot serve (a look-ahead below its δa without look-ahead truncation training) becomes a row with
the one-line reason. Writes ``latency_settings.md`` and ``latency_settings.png`` into ``--out``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import save_figure, write_text_atomic
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.evaluation.speech_following import FollowingConfig, speech_following
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import NUM_JOINTS
from gesturecast.realtime.cli_flags import settings_from_args
from gesturecast.realtime.engine_cli import frames_to_motion
from gesturecast.realtime.generation.generator import check_lookahead
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import LATENCY_SETTINGS

Measure = Callable[..., tuple[dict, "list[PoseFrame] | None"]]  # (args, audio, keep_frames, settings) → result, frames
TABLE_NAME = "latency_settings.md"
PLOT_NAME = "latency_settings.png"


def following_score(frames: list[PoseFrame], audio: np.ndarray) -> dict:
    """Speech following (r_best, lag_s, r_lag0) of the released frames for the (n,) 16 kHz audio."""
    positions = frames_to_motion(sorted(frames, key=lambda f: f.seq)).positions()[:, :NUM_JOINTS]  # (T, 22, 3)
    return speech_following(positions, audio, SAMPLE_RATE, MOTION_FPS, FollowingConfig()).to_dict()


def setting_row(model: Path, setting: str, result: dict, following: dict) -> dict:
    windows = [result.get(name, {}) for name in ("start", "after_start")]
    return {
        "model": str(model),
        "latency": setting,
        "lookahead_frames": result["settings"]["lookahead_frames"],
        "compute_margin_ms": result["settings"]["compute_margin_ms"],
        "latency_budget_ms": result["latency_budget_ms"],
        "end_to_end_ms": {p: result["end_to_end_ms"][p] for p in ("p50", "p95", "p99")},
        "margin_used_ms": result["margin_used_ms"],
        "deadline_misses": result["deadline_misses"],
        "late_frames": sum(window.get("late_frames", 0) for window in windows),
        "rtf": result["rtf"],
        "following": following,
        "frames": result["frames"],
    }


def sweep_rows(args: argparse.Namespace, audio: Path, measure: Measure) -> list[dict]:
    """One real-time run per model and setting (a skipped row, with the reason, where a model cannot serve it)."""
    samples = load_audio(audio)  # (n,)
    rows = []
    for model in [args.model, *args.sweep_models]:
        for setting in LATENCY_SETTINGS:
            settings = settings_from_args(args, model=model, latency=setting, lookahead=None, margin_ms=None)
            config = load_bundle(model).denoiser_config
            try:
                check_lookahead(config, LATENCY_SETTINGS[setting].lookahead_for(config.audio_lookahead))
            except UserError as error:
                rows.append({"model": str(model), "latency": setting, "skipped": str(error)})
                continue
            result, frames = measure(args, audio, keep_frames=True, settings=settings)
            rows.append(setting_row(model, setting, result, following_score(frames, samples)))
    return rows


def table(rows: list[dict]) -> str:
    lines = ["| model | latency | δ | margin ms | L ms | p50 ms | p95 ms | p99 ms | misses | late > 33 ms | rtf "
             "| following r |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "skipped" in r:
            lines.append(f"| {r['model']} | {r['latency']} | – | – | – | – | – | – | – | – | – | not served "
                         "(trained without look-ahead truncation) |")
            continue
        e2e = r["end_to_end_ms"]
        lines.append(
            f"| {r['model']} | {r['latency']} | {r['lookahead_frames']} | {r['compute_margin_ms']:.0f} | "
            f"{r['latency_budget_ms']:.0f} | {e2e['p50']:.0f} | {e2e['p95']:.0f} | {e2e['p99']:.0f} | "
            f"{r['deadline_misses']} | {r['late_frames']} | {r['rtf']:.3f} | {r['following']['r_best']:.3f} |")
    return "\n".join(lines) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    """Left: L and end-to-end p95 per setting; right: following r per setting; one colour per model."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    names = list(LATENCY_SETTINGS)
    measured = [r for r in rows if "skipped" not in r]
    for index, model in enumerate(dict.fromkeys(r["model"] for r in measured)):
        subset = [r for r in measured if r["model"] == model]
        x = [names.index(r["latency"]) for r in subset]
        colour = f"C{index}"
        label = Path(model).name or model
        left.plot(x, [r["latency_budget_ms"] for r in subset], "s:", color=colour, label=f"{label}: L")
        left.plot(x, [r["end_to_end_ms"]["p95"] for r in subset], "o-", color=colour, label=f"{label}: p95")
        right.plot(x, [r["following"]["r_best"] for r in subset], "o-", color=colour, label=label)
    left.axhline(250.0, linestyle="--", color="grey", linewidth=0.8)
    left.set(ylabel="ms", title="latency L and end-to-end p95 (dashed: 250 ms)")
    right.set(ylabel="speech following r (best lag)", title="following of the released motion")
    for axis in (left, right):
        axis.set_xticks(range(len(names)), names)
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8)
    figure.tight_layout()
    save_figure(figure, path, dpi=110)
    plt.close(figure)


def latency_sweep(args: argparse.Namespace, audio: Path, measure: Measure) -> dict:
    """Run the sweep, write the table and the plot into ``args.out``; the JSON object of ``bench latency``."""
    rows = sweep_rows(args, audio, measure)
    args.out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out / TABLE_NAME, table(rows))
    plot(rows, args.out / PLOT_NAME)
    return {"settings": rows, "table": str(args.out / TABLE_NAME), "plot": str(args.out / PLOT_NAME)}
