"""Where a gesture clip means most: the body frame and the stroke, shared by the lexicon's builder and a user clip.

**Body frame** (:func:`body_frame_positions`): joint positions relative to the hips, turned into the hips' facing
frame of the same frame (x = the character's left, y = up, z = forward), so walking or turning does not count as
gesturing.

**Stroke** (:func:`stroke_frame`): the peak of a signal inside a segment, taken at its arrival: the first frame that
comes within ``STROKE_TOLERANCE`` (5 %) of the signal's range below the peak, so a held pose gives the moment it is
reached rather than a frame picked by tremor inside the hold. A user clip without a ``stroke`` takes it on
:func:`pose_distance`, how far the wrists and head are from the clip's first pose; the lexicon's builder takes it on
its gesture rules (:mod:`gesturecast.tools.gestures.build`). Numpy only (no torch).
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import facing_yaw, rotate_planar
from gesturecast.models.motion.skeleton import CANONICAL

ACTIVITY_JOINTS = ("LeftHand", "RightHand", "Head")  # the joints whose motion is the gesture
STROKE_TOLERANCE = 0.05
RELEASE_LEVEL = 0.75  # a clip's hold ends at the last frame its wrists and head are this near their farthest


def body_frame_positions(motion: SkeletonMotion) -> np.ndarray:
    """(T, J, 3) joint positions relative to the hips in the hips' facing frame: x left, y up, z forward."""
    positions = motion.positions()
    relative = positions - positions[:, :1]
    yaw = facing_yaw(motion.rotations[:, 0])  # (T,)
    planar = rotate_planar(relative[..., [0, 2]], -yaw[:, None])  # (T, J, 2)
    return np.stack([planar[..., 0], relative[..., 1], planar[..., 1]], axis=-1)


def stroke_frame(signal: np.ndarray, start: int = 0, stop: int | None = None,
                 tolerance: float = STROKE_TOLERANCE) -> int:
    """The frame (absolute) of the signal's peak inside ``[start, stop)``, at its arrival: the first frame within
    ``tolerance`` of the signal's range there below the peak."""
    stop = len(signal) if stop is None else stop
    window = signal[start:stop]
    if len(window) == 0:
        raise ValueError("empty segment")
    peak, low = float(window.max()), float(window.min())
    reached = np.flatnonzero(window >= peak - tolerance * (peak - low))
    return start + int(reached[0])


def pose_distance(body: np.ndarray, reference: int = 0) -> np.ndarray:
    """(T,) summed distance (m) of the wrists and head from their place at frame ``reference`` (body frame)."""
    joints = [CANONICAL.index(name) for name in ACTIVITY_JOINTS]
    return np.linalg.norm(body[:, joints] - body[reference, joints], axis=-1).sum(axis=-1)


def release_frame(body: np.ndarray) -> int:
    """The last frame of a clip's hold: after it, the wrists and head only come back toward their first pose (the
    last frame their :func:`pose_distance` from it is at least :data:`RELEASE_LEVEL` of its peak)."""
    distance = pose_distance(body)
    return int(np.flatnonzero(distance >= RELEASE_LEVEL * distance.max())[-1])
