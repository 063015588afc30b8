"""Frame-rate conversion of canonical motion: slerp for rotations, linear for the root."""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.rotations import quat_slerp

# rates this close (relative) count as equal: BVH files often round the frame time
# (``Frame Time: 0.0333333`` is 30.00003 fps) and resampling those would only blur them
SAME_RATE_TOLERANCE = 1e-4


def resample_motion(motion: SkeletonMotion, fps: float = MOTION_FPS) -> SkeletonMotion:
    """Resample ``motion`` to ``fps``; output frame k is the pose at time k / fps.

    The output covers the input's time span [0, (T - 1) / motion.fps].
    """
    if fps <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    if abs(motion.fps / fps - 1.0) < SAME_RATE_TOLERANCE:
        return SkeletonMotion(motion.rotations, motion.root_position, fps, motion.skeleton)
    span = (motion.num_frames - 1) / motion.fps
    num_out = int(np.floor(span * fps + 1e-9)) + 1
    source_index = np.arange(num_out) * (motion.fps / fps)  # (T_out,) fractional input frame
    lower = np.minimum(np.floor(source_index).astype(int), motion.num_frames - 1)
    upper = np.minimum(lower + 1, motion.num_frames - 1)
    frac = source_index - lower  # (T_out,)
    rotations = quat_slerp(motion.rotations[lower], motion.rotations[upper], frac[:, None])  # (T_out, J, 4)
    root = motion.root_position[lower] + frac[:, None] * (motion.root_position[upper] - motion.root_position[lower])
    return SkeletonMotion(rotations, root, fps, motion.skeleton)
