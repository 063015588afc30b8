"""Canonical motion written as a CMU-style BVH (cgspeed naming and proportions): a skeleton the model never saw.

The CMU hierarchy has two joints the canonical one lacks (``LHipJoint``/``RHipJoint`` between the hips and
the thighs, ``Neck1`` between the neck and the head); they keep an identity rotation, so the canonical local
rotations carry over joint for joint (identity = T-pose on both). Bone lengths are CMU's, in CMU length
units (about 5.6 cm); the root path is scaled by the ratio of the two skeletons' hip heights, as the
retargeter (docs/retargeting.md) scales it back. Channels: root positions, then ``Zrotation Yrotation
Xrotation`` on every joint, as the cgspeed conversion writes them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.models.motion.bvh import BvhData, rotation_channel_values, write_bvh
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.resample import resample_motion
from gesturecast.models.motion.rest_alignment import hip_height
from gesturecast.models.motion.rotations import quat_identity
from gesturecast.models.motion.skeleton import CANONICAL, Skeleton

CMU_FPS = 120.0
ROTATION_ORDER = "ZYX"
_ROTATION_CHANNELS = tuple(f"{axis}rotation" for axis in ROTATION_ORDER)
_ROOT_CHANNELS = ("Xposition", "Yposition", "Zposition", *_ROTATION_CHANNELS)


def _cmu_table() -> list[tuple[str, str | None, str | None, tuple[float, float, float]]]:
    """(CMU name, parent, canonical joint whose rotation it carries or None, rest offset), depth-first."""
    table: list[tuple[str, str | None, str | None, tuple[float, float, float]]] = [("Hips", None, "Hips", (0, 0, 0))]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        hip = f"{side[0]}HipJoint"
        table += [(hip, "Hips", None, (0, 0, 0)), (f"{side}UpLeg", hip, f"{side}UpperLeg", (sign * 1.45, -0.35, 0)),
                  (f"{side}Leg", f"{side}UpLeg", f"{side}LowerLeg", (0, -7.1, 0)),
                  (f"{side}Foot", f"{side}Leg", f"{side}Foot", (0, -7.3, 0)),
                  (f"{side}ToeBase", f"{side}Foot", f"{side}Toes", (0, 0, 2.2))]
    table += [("LowerBack", "Hips", "Spine", (0, 0, 0)), ("Spine", "LowerBack", "Chest", (0, 2.1, 0)),
              ("Spine1", "Spine", "UpperChest", (0, 2.1, 0)), ("Neck", "Spine1", "Neck", (0, 0, 0)),
              ("Neck1", "Neck", None, (0, 1.6, 0)), ("Head", "Neck1", "Head", (0, 1.7, 0))]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        table += [(f"{side}Shoulder", "Spine1", f"{side}Shoulder", (0, 0, 0)),
                  (f"{side}Arm", f"{side}Shoulder", f"{side}UpperArm", (sign * 3.4, 1.2, 0)),
                  (f"{side}ForeArm", f"{side}Arm", f"{side}LowerArm", (sign * 5.2, 0, 0)),
                  (f"{side}Hand", f"{side}ForeArm", f"{side}Hand", (sign * 3.8, 0, 0))]
    return table


CMU_TABLE = _cmu_table()
CMU_NAMES = tuple(row[0] for row in CMU_TABLE)
_END_SITES = {"Head": (0, 1.5, 0), "LeftHand": (1.5, 0, 0), "RightHand": (-1.5, 0, 0), "LeftToeBase": (0, 0, 0.8),
              "RightToeBase": (0, 0, 0.8)}


def cmu_skeleton() -> Skeleton:
    """The CMU hierarchy with its rest offsets (CMU units)."""
    parents = tuple(-1 if parent is None else CMU_NAMES.index(parent) for _, parent, _, _ in CMU_TABLE)
    return Skeleton(CMU_NAMES, parents, np.array([row[3] for row in CMU_TABLE], np.float64))


def rest_hip_height(skeleton: Skeleton) -> float:
    """Height of the hips above the lowest joint in the T-pose (the skeleton's length units)."""
    _, positions = skeleton.forward_kinematics(quat_identity((skeleton.num_joints,)), np.zeros(3))  # (J, 3)
    return hip_height(positions)


def cmu_bvh_data(motion: SkeletonMotion, fps: float = CMU_FPS) -> BvhData:
    """Canonical ``motion`` (any rate) resampled to ``fps`` on the CMU skeleton."""
    resampled = resample_motion(motion, fps)
    skeleton = cmu_skeleton()
    units_per_metre = rest_hip_height(skeleton) / rest_hip_height(CANONICAL)
    rotations = quat_identity((resampled.num_frames, len(CMU_NAMES)))  # (T, J', 4)
    for j, (_, _, canonical, _) in enumerate(CMU_TABLE):
        if canonical is not None:
            rotations[:, j] = resampled.rotations[:, CANONICAL.index(canonical)]
    euler = rotation_channel_values(rotations, ROTATION_ORDER).reshape(resampled.num_frames, -1)  # (T, 3 J')
    values = np.concatenate([resampled.root_position * units_per_metre, euler], axis=1)  # (T, 3 + 3 J')
    channels = [_ROOT_CHANNELS] + [_ROTATION_CHANNELS] * (len(CMU_NAMES) - 1)
    end_sites = {CMU_NAMES.index(name): np.array(offset, np.float64) for name, offset in _END_SITES.items()}
    return BvhData(list(CMU_NAMES), np.array(skeleton.parents), skeleton.offsets, channels, 1.0 / fps, values,
                   end_sites)


def write_cmu_bvh(motion: SkeletonMotion, path: Path, fps: float = CMU_FPS) -> Path:
    write_bvh(cmu_bvh_data(motion, fps), path)
    return path
