"""Joint-space reconstruction error of motion features: root-relative positions (cm) and rotations (degrees)."""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.motion_features import ROOT_VELOCITY, ROOT_YAW_RATE, features_to_motion
from gesturecast.models.motion.skeleton import CANONICAL

CENTIMETRES_PER_METRE = 100.0


def rotation_angle_degrees(q_a: np.ndarray, q_b: np.ndarray) -> np.ndarray:
    """Angle of the relative rotation between unit quaternions (..., 4) → (...) degrees."""
    dot = np.clip(np.abs(np.sum(q_a * q_b, axis=-1)), 0.0, 1.0)
    return np.degrees(2.0 * np.arccos(dot))


def in_facing_frame(features: np.ndarray) -> np.ndarray:
    """Features with the planar root motion removed, so poses are compared in each frame's facing frame."""
    still = np.array(features, dtype=np.float64)  # (T, D)
    still[:, ROOT_VELOCITY] = 0.0
    still[:, ROOT_YAW_RATE] = 0.0
    return still


def joint_errors(reference: np.ndarray, reconstruction: np.ndarray,
                 joints: tuple[str, ...] | None = None) -> dict[str, float]:
    """Mean root-relative joint position error (cm) and mean local rotation error (degrees) of two (T, D)
    denormalised feature clips, both seen in their own facing frame (root drift is not counted); over the
    named canonical ``joints`` only when given (a body part's)."""
    motion_a = features_to_motion(in_facing_frame(reference))
    motion_b = features_to_motion(in_facing_frame(reconstruction))
    picked = slice(None) if joints is None else [CANONICAL.index(joint) for joint in joints]
    positions_a = (motion_a.positions() - motion_a.root_position[:, None])[:, picked]  # (T, J', 3)
    positions_b = (motion_b.positions() - motion_b.root_position[:, None])[:, picked]  # (T, J', 3)
    position_error = np.linalg.norm(positions_a - positions_b, axis=-1).mean() * CENTIMETRES_PER_METRE
    rotation_error = rotation_angle_degrees(motion_a.rotations[:, picked], motion_b.rotations[:, picked])  # (T, J')
    return {"position_cm": float(position_error), "rotation_deg": float(rotation_error.mean())}
