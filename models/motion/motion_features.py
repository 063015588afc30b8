"""The model's per-frame motion feature vector and the motion-level operations around it.

Feature layout (``FEATURE_DIM`` = 4 + 6 * NUM_JOINTS = 136 for the canonical skeleton), frame t:

==========  =====================================================================================
index       content
==========  =====================================================================================
0           hips height y (metres)
1, 2        planar hips velocity (x, z) from frame t-1 to t, in metres per frame, expressed in the
            facing frame of frame t-1 (0 at t = 0)
3           yaw rate: facing yaw of frame t minus facing yaw of frame t-1, wrapped to (-pi, pi]
            radians per frame (0 at t = 0)
4 .. 9      hips rotation with the facing yaw removed, 6D (Zhou et al. 2019, CVPR, Sec. 4)
10 ..       every other joint's local rotation in 6D, canonical joint order (6 values per joint)
==========  =====================================================================================

The root channels are backward differences, so a streaming decoder can integrate them frame by
frame as they arrive (:class:`RootIntegrator`); :func:`features_to_motion` uses the same
integrator, so the offline and streaming trajectories are identical.

Facing: the yaw of the hips' rotated left axis (+X) projected onto the ground. The lateral axis
stays horizontal when the hips pitch (bows, leaning), where the rotated forward axis would not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.rotations import (
    quat_from_6d,
    quat_from_yaw,
    quat_mul,
    quat_rotate,
    quat_slerp,
    quat_to_6d,
)
from gesturecast.models.motion.skeleton import CANONICAL, NUM_JOINTS, Skeleton

ROOT_HEIGHT = slice(0, 1)
ROOT_VELOCITY = slice(1, 3)
ROOT_YAW_RATE = slice(3, 4)
ROOT_DIM = 4
ROTATION_6D_DIM = 6
FEATURE_DIM = ROOT_DIM + ROTATION_6D_DIM * NUM_JOINTS
_LEFT_AXIS = np.array([1.0, 0.0, 0.0])


def feature_dim(skeleton: Skeleton = CANONICAL) -> int:
    """Feature width for a skeleton (``FEATURE_DIM`` for the canonical one)."""
    return ROOT_DIM + ROTATION_6D_DIM * skeleton.num_joints


def facing_yaw(hips_rotation: np.ndarray) -> np.ndarray:
    """Facing yaw (radians about +Y, 0 = facing +Z) from hips rotations. (..., 4) -> (...)."""
    left = quat_rotate(hips_rotation, np.broadcast_to(_LEFT_AXIS, (*hips_rotation.shape[:-1], 3)))
    # a character facing yaw has its left axis at (cos yaw, 0, -sin yaw)
    return np.arctan2(-left[..., 2], left[..., 0])


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def rotate_planar(vectors_xz: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Rotate (..., 2) ground-plane (x, z) vectors about +Y by ``yaw`` (...)."""
    cos, sin = np.cos(yaw), np.sin(yaw)
    x, z = vectors_xz[..., 0], vectors_xz[..., 1]
    return np.stack([cos * x + sin * z, -sin * x + cos * z], axis=-1)


def motion_to_features(motion: SkeletonMotion) -> np.ndarray:
    """Per-frame features (T, D) float32 — a pure function of the motion (layout: module doc)."""
    rotations = motion.rotations  # (T, J, 4)
    num_frames = motion.num_frames
    yaw = facing_yaw(rotations[:, 0])  # (T,)
    planar = motion.root_position[:, [0, 2]]  # (T, 2)
    velocity = np.zeros((num_frames, 2))
    velocity[1:] = rotate_planar(planar[1:] - planar[:-1], -yaw[:-1])  # (T-1, 2) in facing frame of t-1
    yaw_rate = np.zeros(num_frames)
    yaw_rate[1:] = wrap_angle(np.diff(yaw))
    local = rotations.copy()
    local[:, 0] = quat_mul(quat_from_yaw(-yaw), rotations[:, 0])  # hips without facing yaw
    six_d = quat_to_6d(local).reshape(num_frames, -1)  # (T, J * 6)
    root = np.concatenate([motion.root_position[:, 1:2], velocity, yaw_rate[:, None]], axis=1)  # (T, 4)
    return np.concatenate([root, six_d], axis=1).astype(np.float32)


@dataclass
class RootIntegrator:
    """Streaming reconstruction of the hips trajectory from the root feature channels.

    State: ``position_xz`` and ``yaw`` of the last integrated frame (``None`` before the first).
    ``step`` takes one frame's features and returns (hips position (3,), facing yaw); integrating
    a whole clip frame by frame equals :func:`features_to_motion` exactly (it uses this class).
    """

    start_position_xz: tuple[float, float] = (0.0, 0.0)
    start_yaw: float = 0.0
    position_xz: np.ndarray | None = None
    yaw: float | None = None

    def reset(self) -> None:
        self.position_xz = None
        self.yaw = None

    def step(self, frame_features: np.ndarray) -> tuple[np.ndarray, float]:
        frame_features = np.asarray(frame_features, dtype=np.float64)
        if self.position_xz is None or self.yaw is None:
            self.position_xz = np.array(self.start_position_xz, dtype=np.float64)
            self.yaw = float(self.start_yaw)
        else:
            displacement = rotate_planar(frame_features[ROOT_VELOCITY], np.float64(self.yaw))
            self.position_xz = self.position_xz + displacement
            self.yaw = float(wrap_angle(self.yaw + frame_features[ROOT_YAW_RATE][0]))
        position = np.array([self.position_xz[0], frame_features[ROOT_HEIGHT][0], self.position_xz[1]])
        return position, self.yaw


def features_to_rotations(features: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Local rotations (..., J, 4) from features (..., D) and the integrated facing yaw (...)."""
    six_d = features[..., ROOT_DIM:].astype(np.float64).reshape(*features.shape[:-1], -1, ROTATION_6D_DIM)
    rotations = quat_from_6d(six_d)  # (..., J, 4)
    rotations[..., 0, :] = quat_mul(quat_from_yaw(yaw), rotations[..., 0, :])
    return rotations


def features_to_motion(
    features: np.ndarray,
    start_position: tuple[float, float] = (0.0, 0.0),
    start_yaw: float = 0.0,
    fps: float = 30.0,
    skeleton: Skeleton = CANONICAL,
) -> SkeletonMotion:
    """Inverse of :func:`motion_to_features`: integrate the root, decode 6D rotations.

    ``start_position`` is the planar (x, z) hips position and ``start_yaw`` the facing yaw of the
    first frame (the features only hold their changes).
    """
    integrator = RootIntegrator(start_position, start_yaw)
    steps = [integrator.step(frame) for frame in features]
    root_position = np.array([position for position, _ in steps]).reshape(-1, 3)  # (T, 3)
    yaw = np.array([yaw for _, yaw in steps])  # (T,)
    return SkeletonMotion(features_to_rotations(features, yaw), root_position, fps, skeleton)


def face_forward(motion: SkeletonMotion) -> SkeletonMotion:
    """Rotate about +Y so the first frame faces +Z, and move its planar hips position to the origin."""
    yaw0 = facing_yaw(motion.rotations[0, 0])
    turn = quat_from_yaw(-yaw0)  # (4,)
    rotations = motion.rotations.copy()
    rotations[:, 0] = quat_mul(np.broadcast_to(turn, rotations[:, 0].shape), rotations[:, 0])
    planar = motion.root_position[:, [0, 2]] - motion.root_position[0, [0, 2]]  # (T, 2)
    root = motion.root_position.copy()
    root[:, [0, 2]] = rotate_planar(planar, -yaw0)
    return SkeletonMotion(rotations, root, motion.fps, motion.skeleton)


def mirror_motion(motion: SkeletonMotion) -> SkeletonMotion:
    """Left/right mirror: swap Left*/Right* joints and reflect the X axis (an exact involution).

    A reflection S = diag(-1, 1, 1) maps a rotation R to S R S, i.e. the quaternion
    (x, y, z, w) to (x, -y, -z, w); valid for local rotations because the skeleton's rest offsets
    are themselves mirror-symmetric.
    """
    swap = motion.skeleton.mirror_indices()
    rotations = motion.rotations[:, swap] * np.array([1.0, -1.0, -1.0, 1.0])
    root = motion.root_position * np.array([-1.0, 1.0, 1.0])
    return SkeletonMotion(rotations, root, motion.fps, motion.skeleton)


def speed_perturb(motion: SkeletonMotion, factor: float) -> SkeletonMotion:
    """Play the motion ``factor`` times faster (0.9 = slower, longer), resampled at the same fps.

    Frame i of the result samples the source at time i * factor (in frames): slerp for rotations,
    linear for the hips. The result has ``floor((T - 1) / factor) + 1`` frames.
    """
    if factor <= 0:
        raise ValueError(f"speed factor must be positive, got {factor}")
    num_out = int(np.floor((motion.num_frames - 1) / factor + 1e-9)) + 1
    source_time = np.arange(num_out) * factor  # (T',) in source frames
    lower = np.minimum(np.floor(source_time).astype(int), motion.num_frames - 1)
    upper = np.minimum(lower + 1, motion.num_frames - 1)
    weight = source_time - lower  # (T',)
    joint_weight = np.broadcast_to(weight[:, None], (num_out, motion.skeleton.num_joints))  # (T', J)
    rotations = quat_slerp(motion.rotations[lower], motion.rotations[upper], joint_weight)  # (T', J, 4)
    root = motion.root_position[lower] * (1.0 - weight[:, None]) + motion.root_position[upper] * weight[:, None]
    return SkeletonMotion(rotations, root, motion.fps, motion.skeleton)
