"""``gesturecast bench root FILE``: does the avatar stay where it stands? Root drift per style and root mode.

For every style and root mode the file goes through the product's offline session (the `generate`
path). Reported per run: the largest ground-plane distance of the hips from the first frame, the net
travel (first to last frame), the largest facing yaw away from the start, the largest per-frame hips
step (a pop at the bound would show here) and the hips' mean ground speed. ``--plot`` draws the
ground-plane paths, one panel per style. One JSON object; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gesturecast.controls import ROOT_MODES
from gesturecast.models.motion.motion_features import facing_yaw
from gesturecast.models.motion.root_anchor import RootTravel
from gesturecast.realtime.audio.sources import FastFileSource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock

DEFAULT_STYLES = ("neutral", "happy", "old", "angry")
CM_PER_M = 100.0


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("root", help="root drift (distance, travel, facing) per style and mode")
    parser.add_argument("audio", type=Path, help="speech file")
    add_generation_arguments(parser)
    parser.add_argument("--styles", nargs="+", default=list(DEFAULT_STYLES), help="styles to run")
    parser.add_argument("--modes", nargs="+", choices=ROOT_MODES, default=["bounded", "free"])
    parser.add_argument("--plot", type=Path, help="PNG of the ground-plane hips paths")
    parser.set_defaults(func=run_bench)


def root_path(args: argparse.Namespace, style: str, mode: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(hips positions (T, 3), facing yaw (T,), fps) of one offline run."""
    session = build_session(settings_from_args(args, style=style, root=mode), MonotonicClock())
    frames, _ = run_offline(session, FastFileSource(args.audio))
    positions = np.stack([frame.root_position for frame in frames])  # (T, 3)
    yaws = facing_yaw(np.stack([frame.rotations[0] for frame in frames]))  # (T,)
    return positions, yaws, session.fps


def drift_figures(positions: np.ndarray, yaws: np.ndarray, fps: float) -> dict:
    """Distance, travel and facing as the live summary reports them (:class:`RootTravel`), plus steps and speed."""
    travel = RootTravel()
    for position, yaw in zip(positions, yaws, strict=True):
        travel.update(position, yaw)
    steps = np.linalg.norm(np.diff(positions[:, [0, 2]], axis=0), axis=1)  # (T-1,) ground-plane steps
    return {
        "seconds": round(len(positions) / fps, 2),
        "max_distance_m": round(travel.max_distance_m, 4),
        "net_travel_m": round(travel.net_travel_m, 4),
        "max_facing_deg": round(travel.max_facing_deg, 2),
        "max_step_cm": round(float(steps.max() * CM_PER_M), 3),
        "mean_speed_cm_s": round(float(steps.mean() * fps * CM_PER_M), 3),
    }


def plot_paths(paths: dict[str, dict[str, np.ndarray]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, len(paths), figsize=(4 * len(paths), 4), squeeze=False)
    for axis, (style, by_mode) in zip(axes[0], paths.items(), strict=True):
        for mode, planar in by_mode.items():
            axis.plot(planar[:, 0], planar[:, 1], label=mode, linewidth=0.8)
        axis.set_title(style)
        axis.set_aspect("equal", adjustable="datalim")
        axis.set_xlabel("x (m)")
        axis.set_ylabel("z (m)")
        axis.legend()
    figure.tight_layout()
    figure.savefig(path, dpi=100)


def run_bench(args: argparse.Namespace) -> int:
    runs, paths = [], {}
    for style in args.styles:
        for mode in args.modes:
            positions, yaws, fps = root_path(args, style, mode)
            runs.append({"style": style, "root": mode, **drift_figures(positions, yaws, fps)})
            paths.setdefault(style, {})[mode] = positions[:, [0, 2]] - positions[0, [0, 2]]
    if args.plot is not None:
        plot_paths(paths, args.plot)
    print(json.dumps({"audio": str(args.audio), "runs": runs}, indent=1))
    return 0
