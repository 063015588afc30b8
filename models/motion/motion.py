"""Canonical motion clips: local joint rotations on :data:`CANONICAL` plus the Hips trajectory."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.skeleton import CANONICAL, Skeleton

MOTION_FPS = 30.0


@dataclass
class Motion:
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

    def slice(self, start: int, stop: int) -> Motion:
        return Motion(self.rotations[start:stop], self.root_position[start:stop], self.fps, self.skeleton)
