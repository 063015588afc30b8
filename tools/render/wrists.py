"""Wrist trajectories of several motion files side by side (``gesturecast render --wrists A.bvh B.bvh …``).

One column per file (e.g. real motion, the old default's generation, the new one's, of the same speech);
rows: the front-view path of both wrists, then their x, y and z over time. Positions are in the **body
frame**: the hips' ground point at the origin and the body turned to face +Z, every frame, so walking
and turning do not hide the gestures and a real take compares with an in-place generated one. Each
column's title gives the mean wrist speed and the height range per hand. Needs matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.files import save_figure
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import facing_yaw, rotate_planar
from gesturecast.models.motion.skeleton import CANONICAL

WRISTS = ("LeftHand", "RightHand")
WRIST_COLOURS = ("tab:blue", "tab:red")
AXES = ("x (m, the avatar's left +)", "y (m, up)", "z (m, forward +)")
CM_PER_M = 100.0
COLUMN_SIZE = (4.2, 2.4)  # inches per column and per row
DPI = 110


@dataclass(frozen=True)
class WristTrack:
    label: str
    wrists: np.ndarray  # (T, 2, 3) left and right wrist in the body frame, metres
    fps: float
    start_s: float  # time of the first frame in the file

    def mean_speed_cm_s(self) -> np.ndarray:
        """(2,) mean wrist speed per hand."""
        return np.linalg.norm(np.diff(self.wrists, axis=0), axis=-1).mean(axis=0) * self.fps * CM_PER_M

    def height_range_cm(self) -> np.ndarray:
        """(2,) highest minus lowest wrist height per hand."""
        return np.ptp(self.wrists[..., 1], axis=0) * CM_PER_M


def body_frame_wrists(motion: SkeletonMotion) -> np.ndarray:
    """(T, 2, 3) left and right wrist positions relative to the hips' ground point, turned to face +Z."""
    positions = motion.positions()  # (T, J, 3)
    wrists = positions[:, [CANONICAL.index(name) for name in WRISTS]]  # (T, 2, 3)
    ground = positions[:, 0] * np.array([1.0, 0.0, 1.0])  # (T, 3) hips on the ground plane
    relative = wrists - ground[:, None]  # (T, 2, 3)
    yaw = facing_yaw(motion.rotations[:, 0])  # (T,)
    relative[..., [0, 2]] = rotate_planar(relative[..., [0, 2]], -yaw[:, None])  # undo each frame's facing
    return relative


def plot_wrists(tracks: list[WristTrack], path: Path) -> Path:
    """Draw the tracks, one column each, with shared scales per row; returns the written path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 1 + len(AXES)
    figure, axes = plt.subplots(rows, len(tracks), squeeze=False, sharey="row",
                                figsize=(COLUMN_SIZE[0] * len(tracks), COLUMN_SIZE[1] * rows))
    for column, track in zip(axes.T, tracks, strict=True):
        _draw_column(column, track)
    for row, name in enumerate(("front view: y (m)", *AXES)):
        axes[row, 0].set_ylabel(name)
    axes[0, 0].legend(loc="upper right", fontsize="small")
    figure.tight_layout()
    save_figure(figure, path, dpi=DPI)
    plt.close(figure)
    return path


def _draw_column(column: np.ndarray, track: WristTrack) -> None:
    times = track.start_s + np.arange(len(track.wrists)) / track.fps  # (T,)
    speed, height = track.mean_speed_cm_s(), track.height_range_cm()
    column[0].set_title(f"{track.label}\nspeed L {speed[0]:.0f} / R {speed[1]:.0f} cm/s, "
                        f"height range L {height[0]:.0f} / R {height[1]:.0f} cm", fontsize="small")
    for hand, (name, colour) in enumerate(zip(WRISTS, WRIST_COLOURS, strict=True)):
        column[0].plot(track.wrists[:, hand, 0], track.wrists[:, hand, 1], color=colour, linewidth=0.8, label=name)
        for axis in range(len(AXES)):
            column[1 + axis].plot(times, track.wrists[:, hand, axis], color=colour, linewidth=0.8)
    column[0].set_xlabel("x (m): camera's view of the avatar")
    column[0].set_aspect("equal", adjustable="datalim")
    column[-1].set_xlabel("time (s)")
