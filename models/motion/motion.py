"""Canonical motion clips: local joint rotations on :data:`CANONICAL` plus the Hips trajectory."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.skeleton import CANONICAL, Skeleton

MOTION_FPS = 30.0
# motion files (BVH, SMPL-X .npz): limits checked from the header before anything is allocated
MIN_FILE_FPS = 1.0  # a BVH ``Frame Time`` of at most 1 s
MAX_FILE_FPS = 1000.0  # a ``Frame Time`` of at least 1 ms
MAX_CLIP_SECONDS = 4 * 3600.0  # 4 h: 432 000 frames at 30 fps, about 300 MB of canonical rotations
# a BVH file, or one decompressed array of an .npz: loading and retargeting take about 8 times a BVH's size at
# their peak (a 68 MB BVH, 24 min of 52 joints: 0.5 GB), so 256 MiB stays near 2 GB; real takes are 1-30 MB
MAX_MOTION_FILE_BYTES = 256 << 20
MAX_ROOT_METRES = 1000.0  # the Hips path of a loaded clip (after scaling to the canonical skeleton): 1 km


def check_file_size(num_bytes: int, source: str) -> None:
    """Refuse a motion file (or .npz member, by its declared size) above :data:`MAX_MOTION_FILE_BYTES`."""
    if num_bytes > MAX_MOTION_FILE_BYTES:
        raise UserError(f"{source}: {num_bytes / 2**20:.0f} MiB is larger than the supported "
                        f"{MAX_MOTION_FILE_BYTES / 2**20:.0f} MiB for a motion file")


def check_clip_header(fps: float, num_frames: int, source: str) -> None:
    """Refuse a motion file whose frame rate or implied length (frames / fps) is outside the limits."""
    if not MIN_FILE_FPS <= fps <= MAX_FILE_FPS:
        raise UserError(f"{source}: frame rate {fps:g} fps is outside the supported {MIN_FILE_FPS:g}-"
                        f"{MAX_FILE_FPS:g} fps (BVH Frame Time {1 / MAX_FILE_FPS:g}-{1 / MIN_FILE_FPS:g} s)")
    if num_frames / fps > MAX_CLIP_SECONDS:
        raise UserError(f"{source}: {num_frames} frames at {fps:g} fps is {num_frames / fps / 3600:.1f} h, "
                        f"longer than the supported {MAX_CLIP_SECONDS / 3600:g} h")


def check_rotations(rotations: np.ndarray, source: str) -> None:
    """Refuse a loaded clip whose rotations (T, J, 4) are not finite."""
    if not np.isfinite(rotations).all():
        raise UserError(f"{source}: the joint rotations hold NaN or infinite values")


def check_root_path(root_position: np.ndarray, source: str) -> None:
    """Refuse a loaded clip whose Hips path (T, 3), in metres, is not finite or leaves :data:`MAX_ROOT_METRES`."""
    if not np.isfinite(root_position).all():
        raise UserError(f"{source}: the Hips path holds NaN or infinite values")
    farthest = float(np.abs(root_position).max(initial=0.0))
    if farthest > MAX_ROOT_METRES:
        raise UserError(f"{source}: the Hips reach {farthest:g} m from the origin, beyond the supported "
                        f"{MAX_ROOT_METRES:g} m")


@dataclass
class SkeletonMotion:
    """A clip on the canonical skeleton.

    rotations: (T, J, 4) local XYZW rotations, identity = T-pose.
    root_position: (T, 3) world position of the Hips in metres (Y-up, faces +Z).
    fps: frames per second (the model works at :data:`MOTION_FPS`).
    """

    rotations: np.ndarray
    root_position: np.ndarray
    fps: float = MOTION_FPS
    skeleton: Skeleton = CANONICAL

    def __post_init__(self) -> None:
        if self.rotations.ndim != 3 or self.rotations.shape[1:] != (self.skeleton.num_joints, 4):
            raise ValueError(f"rotations must be (T, {self.skeleton.num_joints}, 4), got {self.rotations.shape}")
        if self.root_position.shape != (self.rotations.shape[0], 3):
            raise ValueError(f"root_position must be ({self.rotations.shape[0]}, 3), got {self.root_position.shape}")

    @property
    def num_frames(self) -> int:
        return self.rotations.shape[0]

    @property
    def duration(self) -> float:
        return self.num_frames / self.fps

    def positions(self) -> np.ndarray:
        """World joint positions (T, J, 3) in metres."""
        return self.skeleton.forward_kinematics(self.rotations, self.root_position)[1]

    def slice(self, start: int, stop: int) -> SkeletonMotion:
        return SkeletonMotion(self.rotations[start:stop], self.root_position[start:stop], self.fps, self.skeleton)
