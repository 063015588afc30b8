"""What ``bench styles`` measures on generated motion (numpy only; definitions in docs/style-study.md).

- :func:`mean_pose_difference_deg`: how far apart two clips' average upper-body poses are — per joint the
  angle between the two clips' mean local rotations (Markley et al. 2007 quaternion average), averaged;
- :func:`part_signature`: one body part's style read from the motion — per joint of the part, the mean and
  standard deviation over time of its local rotation (6D, Zhou et al. 2019; the hips without their heading)
  and its mean speed relative to the root (m/s);
- :func:`seam_roughness`: joint-angle discontinuity where two parts meet — the mean magnitude of the second
  time-difference of a joint's local rotation (angular acceleration, degrees / frame²) at the *border
  joints* (the first joint of a part whose parent belongs to another part) and, for scale, at the others.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.evaluation.beat_consistency import joint_speeds
from gesturecast.models.evaluation.metrics import root_relative
from gesturecast.models.motion.body_parts import ARM_JOINTS, PART_JOINTS, TORSO_JOINTS
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.rotations import (
    quat_conj,
    quat_from_yaw,
    quat_mul,
    quat_to_6d,
    quat_to_axis_angle,
    quat_yaw,
)
from gesturecast.models.motion.skeleton import CANONICAL

UPPER_BODY = TORSO_JOINTS + ARM_JOINTS
ROOT = 0


def _indices(joints: tuple[str, ...]) -> list[int]:
    return [CANONICAL.index(joint) for joint in joints]


def mean_rotations(rotations: np.ndarray) -> np.ndarray:
    """(T, J, 4) → (J, 4): per joint the unit eigenvector of Σ_t q_t q_tᵀ with the largest eigenvalue (sign-free)."""
    scatter = np.einsum("tji,tjk->jik", rotations, rotations)  # (J, 4, 4)
    _, vectors = np.linalg.eigh(scatter)  # eigenvalues ascending
    return vectors[:, :, -1]  # (J, 4)


def rotation_angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (degrees) of the rotation between unit quaternions a and b. (..., 4) x (..., 4) → (...)."""
    dot = np.abs(np.sum(a * b, axis=-1))
    return np.degrees(2.0 * np.arccos(np.clip(dot, 0.0, 1.0)))


def mean_pose_difference_deg(a: np.ndarray, b: np.ndarray, joints: tuple[str, ...] = UPPER_BODY) -> float:
    """Mean over ``joints`` of the angle between the mean local rotations of clips a (T, J, 4) and b (T', J, 4)."""
    index = _indices(joints)
    return float(rotation_angle_deg(mean_rotations(a[:, index]), mean_rotations(b[:, index])).mean())


def without_heading(rotations: np.ndarray) -> np.ndarray:
    """(T, J, 4) with the root's rotation about +Y (the facing, which drifts) taken out."""
    result = rotations.copy()
    result[:, ROOT] = quat_mul(quat_from_yaw(-quat_yaw(rotations[:, ROOT])), rotations[:, ROOT])
    return result


def part_signature(rotations: np.ndarray, positions: np.ndarray, part: str, fps: float = MOTION_FPS) -> np.ndarray:
    """(13·P,) signature of body part ``part`` (P joints) of a clip: rotations (T, J, 4), positions (T, J, 3)."""
    index = _indices(PART_JOINTS[part])
    six_d = quat_to_6d(without_heading(rotations)[:, index])  # (T, P, 6)
    speeds = joint_speeds(root_relative(positions), fps)[:, index]  # (T, P) m/s
    return np.concatenate([six_d.mean(axis=0).ravel(), six_d.std(axis=0).ravel(), speeds.mean(axis=0)])


def signature_distances(result: np.ndarray, own: np.ndarray, other: np.ndarray) -> dict:
    """Euclidean distances of a part's signature to the single-style runs of its own and of the other prompt;
    ``share`` = d_own / (d_own + d_other): 0 = like its own prompt, 0.5 = halfway, 1 = like the other;
    ``progress``: how far the part went from the other prompt's run toward its own prompt's run, the projection
    (r − o)·(w − o) / |w − o|² (0 = like the other prompt, 1 = like its own)."""
    d_own, d_other = float(np.linalg.norm(result - own)), float(np.linalg.norm(result - other))
    total, apart = d_own + d_other, own - other
    span = float(np.dot(apart, apart))
    return {"to_own": d_own, "to_other": d_other, "share": d_own / total if total > 0 else None,
            "progress": float(np.dot(result - other, apart)) / span if span > 0 else None,
            "prompts_apart": float(np.sqrt(span)), "closer_to_own": d_own < d_other}


def border_joints() -> tuple[str, ...]:
    """Joints whose parent belongs to another body part (LeftShoulder, RightShoulder, Spine)."""
    part_of = {joint: part for part, joints in PART_JOINTS.items() for joint in joints}
    return tuple(name for name, parent in zip(CANONICAL.names, CANONICAL.parents, strict=True)
                 if parent >= 0 and part_of[CANONICAL.names[parent]] != part_of[name])


def angular_acceleration_deg(rotations: np.ndarray) -> np.ndarray:
    """(T, J, 4) local rotations → (J,) mean |Δ²θ| in degrees / frame², Δθ_t = log(q_{t+1} q_t⁻¹) (parent frame)."""
    velocity = quat_to_axis_angle(quat_mul(rotations[1:], quat_conj(rotations[:-1])))  # (T-1, J, 3) rad / frame
    return np.degrees(np.linalg.norm(np.diff(velocity, axis=0), axis=-1).mean(axis=0))  # (J,)


def seam_roughness(rotations: np.ndarray) -> dict:
    """Angular acceleration (degrees / frame²) at the border joints (mean and per joint) and at the other joints."""
    acceleration = angular_acceleration_deg(rotations)  # (J,)
    borders = border_joints()
    inner = [j for j, name in enumerate(CANONICAL.names) if j != ROOT and name not in borders]
    per_joint = {name: float(acceleration[CANONICAL.index(name)]) for name in borders}
    return {"border": float(np.mean(list(per_joint.values()))), "inner": float(acceleration[inner].mean()),
            "per_joint": per_joint}
