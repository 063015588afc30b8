"""`gesturecast render IN -o OUT.gif|.mp4|.png`: look at a motion file as a stick figure.

By default the file is retargeted onto the canonical skeleton (what the model sees; a BVH written by
gesturecast keeps its finger joints); ``--raw`` draws the BVH's own skeleton instead, in its file units.
``--wrists`` draws the wrist trajectories of one or more files side by side instead (:mod:`wrists`);
``--compare`` draws several files as rows of one PNG, at the same times (:mod:`compare`).
"""

from __future__ import annotations

import argparse
import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.arguments import finite_float, int_at_least
from gesturecast.errors import UserError
from gesturecast.files import check_distinct
from gesturecast.models.motion.rotations import quat_identity, quat_mul, quat_rotate
from gesturecast.tools.render.animation import RenderConfig, render_positions
from gesturecast.tools.render.compare import CompareRow, render_comparison
from gesturecast.tools.render.wrists import WristTrack, body_frame_wrists, plot_wrists

log = logging.getLogger(__name__)

DEFAULT_WRIST_SECONDS = 5.0
MAX_AUTO_FRAMES = 900  # without --stride, longer GIF/MP4 clips are thinned to about this many frames


@dataclass(frozen=True)
class LoadedClip:
    positions: np.ndarray  # (T, J, 3)
    parents: tuple[int, ...]
    names: tuple[str, ...]
    fps: float


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("render", help="draw a .bvh or SMPL-X .npz as a stick figure (front + side)")
    parser.add_argument("input", type=Path, nargs="+",
                        help="motion file: .bvh (any supported skeleton) or SMPL-X .npz (several with --wrists)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="OUT.gif, OUT.mp4 (needs ffmpeg) or OUT.png")
    parser.add_argument("--start", type=finite_float(minimum=0.0), default=0.0, help="first second to draw (default 0)")
    parser.add_argument("--seconds", type=finite_float(minimum=0.0, exclusive_minimum=True), default=None,
                        help="how many seconds to draw (default: all)")
    parser.add_argument("--stride", type=int_at_least(1), default=None,
                        help="draw every K-th frame (default: 1, thinned if long)")
    parser.add_argument("--sheet-frames", type=int_at_least(1), default=RenderConfig.sheet_frames,
                        help="frames on a PNG sheet")
    parser.add_argument("--focus", metavar="JOINT", help="draw only JOINT and the joints under it, zoomed in "
                        "(e.g. LeftLowerArm for the left forearm and hand)")
    parser.add_argument("--raw", action="store_true", help="draw the BVH's own skeleton, without retargeting")
    parser.add_argument("--joint-map", type=Path, help="JSON joint map for a skeleton that is not detected "
                        "automatically (docs/retargeting.md)")
    parser.add_argument("--wrists", action="store_true", help="draw the wrist trajectories of every input side by "
                        f"side (a PNG; --seconds defaults to {DEFAULT_WRIST_SECONDS:g})")
    parser.add_argument("--compare", action="store_true", help="draw every input as one row of a PNG, at the same "
                        "times (--sheet-frames per row), e.g. one speech in several styles")
    parser.add_argument("--labels", help="with --wrists / --compare: comma-separated titles (default: the file names)")
    parser.set_defaults(func=run_render)


def run_render(args: argparse.Namespace) -> int:
    for path in args.input:
        if not path.is_file():
            raise UserError(f"motion file {path} does not exist")
    check_distinct([("input", path) for path in args.input], [("-o", args.output)])
    if args.wrists:
        return run_wrists(args)
    if args.compare:
        return run_compare(args)
    if len(args.input) > 1:
        raise UserError(f"{len(args.input)} motion files given: several are drawn only with --wrists or --compare")
    (path,) = args.input
    clip = load_raw_bvh(path) if args.raw else load_canonical(path, args.joint_map)
    first, positions = select_time_range(clip.positions, clip.fps, args.start, args.seconds)
    stride = args.stride if args.stride is not None else auto_stride(len(positions), args.output)
    config = RenderConfig(stride=stride, sheet_frames=args.sheet_frames, start_s=first / clip.fps, focus=args.focus)
    title = f"{path.name}  ({'raw' if args.raw else 'canonical'}, {clip.fps:g} fps)"
    out = render_positions(positions, clip.parents, args.output, clip.fps, title, clip.names, config)
    log.info("wrote %s (%d frames, stride %d)", out, len(positions), stride)
    return 0


def run_wrists(args: argparse.Namespace) -> int:
    """Wrist trajectories of every input over the same time range, one column each."""
    from gesturecast.models.motion.retarget import load_motion_file

    if args.raw:
        raise UserError("--wrists draws retargeted motion (the canonical wrists): drop --raw")
    if args.output.suffix.lower() != ".png":
        raise UserError(f"--wrists writes a .png, not '{args.output.suffix}'")
    labels = wrist_labels(args.labels, args.input)
    seconds = DEFAULT_WRIST_SECONDS if args.seconds is None else args.seconds
    tracks = []
    for path, label in zip(args.input, labels, strict=True):
        motion = load_motion_file(path, args.joint_map)
        first, wrists = select_time_range(body_frame_wrists(motion), motion.fps, args.start, seconds)
        tracks.append(WristTrack(label, wrists, motion.fps, first / motion.fps))
    log.info("wrote %s", plot_wrists(tracks, args.output))
    return 0


def run_compare(args: argparse.Namespace) -> int:
    """Every input as one row of a PNG, drawn at the same clip times."""
    if args.output.suffix.lower() != ".png":
        raise UserError(f"--compare writes a .png, not '{args.output.suffix}'")
    rows, rates = [], set()
    for path, label in zip(args.input, wrist_labels(args.labels, args.input), strict=True):
        clip = load_canonical(path, args.joint_map)
        _, positions = select_time_range(clip.positions, clip.fps, args.start, args.seconds)
        rows.append(CompareRow(label, positions, clip.parents, clip.names))
        rates.add(clip.fps)
    if len(rates) > 1:
        raise UserError(f"--compare needs files of one frame rate, got {sorted(rates)} fps")
    log.info("wrote %s", render_comparison(rows, args.output, rates.pop(), args.start, args.sheet_frames))
    return 0


def wrist_labels(labels: str | None, paths: list[Path]) -> list[str]:
    """One title per file: ``--labels a,b,c`` or the file names."""
    if labels is None:
        return [path.name for path in paths]
    names = [name.strip() for name in labels.split(",")]
    if len(names) != len(paths):
        raise UserError(f"--labels has {len(names)} names for {len(paths)} files")
    return names


def load_canonical(path: Path, joint_map: Path | None = None) -> LoadedClip:
    from gesturecast.models.motion.retarget import load_motion_file

    motion = load_motion_file(path, joint_map, keep_hands=True)
    return LoadedClip(motion.positions(), motion.skeleton.parents, motion.skeleton.names, motion.fps)


def load_raw_bvh(path: Path) -> LoadedClip:
    from gesturecast.models.motion.bvh import read_bvh

    if path.suffix.lower() != ".bvh":
        raise UserError(f"--raw draws BVH files only, not '{path.suffix}': drop --raw to retarget {path.name}")
    data = read_bvh(path)
    positions = bvh_positions(data.local_rotations(), data.local_translations(), data.parents)
    return LoadedClip(positions, tuple(int(p) for p in data.parents), tuple(data.names), data.fps)


def bvh_positions(local_rotations: np.ndarray, local_translations: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """Forward kinematics with per-frame local translations (BVH position channels).

    local_rotations: (T, J, 4) XYZW; local_translations: (T, J, 3); returns world positions (T, J, 3).
    """
    num_frames, num_joints = local_rotations.shape[:2]
    global_rot = quat_identity((num_frames, num_joints))  # (T, J, 4)
    positions = np.zeros((num_frames, num_joints, 3))  # (T, J, 3)
    for j, parent in enumerate(parents):
        if parent < 0:
            global_rot[:, j] = local_rotations[:, j]
            positions[:, j] = local_translations[:, j]
            continue
        global_rot[:, j] = quat_mul(global_rot[:, parent], local_rotations[:, j])
        positions[:, j] = positions[:, parent] + quat_rotate(global_rot[:, parent], local_translations[:, j])
    return positions


def select_time_range(
    positions: np.ndarray, fps: float, start: float, seconds: float | None
) -> tuple[int, np.ndarray]:
    """(index of the first frame, the positions (T', J, 3) from ``start`` for ``seconds``) of a (T, J, 3) clip."""
    first = int(round(start * fps))
    last = len(positions) if seconds is None else first + int(round(seconds * fps))
    if start < 0 or (seconds is not None and seconds <= 0) or first >= len(positions):
        raise UserError(f"--start/--seconds select no frames of a {len(positions) / fps:.2f} s clip")
    return first, positions[first:last]


def auto_stride(num_frames: int, output: Path) -> int:
    """1, or enough to keep a long GIF/MP4 near MAX_AUTO_FRAMES frames (a PNG sheet needs none)."""
    if output.suffix == ".png" or num_frames <= MAX_AUTO_FRAMES:
        return 1
    stride = math.ceil(num_frames / MAX_AUTO_FRAMES)
    log.info("%d frames: drawing with stride %d (pass --stride 1 or --seconds to change)", num_frames, stride)
    return stride
