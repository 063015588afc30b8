"""Moving PoseFrames built from known rotations, shared by the bridge tests."""

from __future__ import annotations

import time

import numpy as np

from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON  # what the session sends

ARM_SWING_RAD = 0.9
SWING_HZ = 0.5
CAPTURE_AGE_S = 0.05


def moving_frame(seq: int, fps: float = 30.0, clock_now: float | None = None, style: str = "calm") -> PoseFrame:
    """Frame ``seq`` of a motion whose arms swing and hips turn (sinusoids of time)."""
    t = seq / fps
    phase = np.sin(2 * np.pi * SWING_HZ * t)
    rotations = np.tile([0.0, 0.0, 0.0, 1.0], (SKELETON.num_joints, 1))
    rotations[SKELETON.index("LeftUpperArm")] = quat_from_axis_angle(np.array([0.0, 0.0, -ARM_SWING_RAD * phase]))
    rotations[SKELETON.index("RightUpperArm")] = quat_from_axis_angle(np.array([0.0, 0.0, ARM_SWING_RAD * phase]))
    rotations[SKELETON.index("Hips")] = quat_from_axis_angle(np.array([0.0, 0.5 * phase, 0.0]))
    root = SKELETON.offsets[0] + np.array([0.05 * phase, 0.0, 0.0])
    now = time.monotonic() if clock_now is None else clock_now
    return PoseFrame(seq, now - CAPTURE_AGE_S, now, root, rotations, style=style, speaking=seq % 2 == 0)

