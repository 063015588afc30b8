"""A gesture's arms kept in the body's frame when the torso under them is generated.

A clip that moves only the arms (a wave, a cheer) imposes the arms' local joint rotations; the torso under them
stays generated. When the generated chest leans another way than the recorded one, the same local rotations point
the arms elsewhere: a wave's hands came out 8 cm lower than recorded and crept up instead of arriving. So the
shoulders (the first arm joints) are re-attached: the clip's shoulder rotation in the body frame (hips, facing
removed, through spine, chest and upper chest) is kept, and its local rotation recomputed under the generated
torso, ``local = chain_generated⁻¹ · chain_clip · local_clip``. The joints below the shoulder keep the clip's local
rotations.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.body_parts import joint_columns
from gesturecast.models.motion.motion_features import FEATURE_DIM, ROOT_DIM, ROTATION_6D_DIM
from gesturecast.models.motion.rotations import quat_conj, quat_from_6d, quat_mul, quat_to_6d

CHAIN = ("Spine", "Chest", "UpperChest")  # under the shoulders, after the hips
HIPS_COLUMNS = np.arange(ROOT_DIM, ROOT_DIM + ROTATION_6D_DIM)  # the hips' rotation, facing removed
ARM_ROOTS = ("LeftShoulder", "RightShoulder")


def chain_rotation(features: np.ndarray) -> np.ndarray:
    """(n, D) motion features → (n, 4) the upper chest's rotation in the body frame (hips, spine, chest, upper
    chest composed)."""
    rotation = quat_from_6d(features[:, HIPS_COLUMNS].astype(np.float64))  # (n, 4)
    for joint in CHAIN:
        rotation = quat_mul(rotation, quat_from_6d(features[:, joint_columns(joint)].astype(np.float64)))
    return rotation


def chain_columns() -> np.ndarray:
    """The feature columns of the torso chain under the shoulders (hips included)."""
    return np.concatenate([HIPS_COLUMNS, *[joint_columns(joint) for joint in CHAIN]])


def body_frame_shoulders(features: np.ndarray, columns: np.ndarray) -> list[tuple[list[int], np.ndarray]]:
    """The shoulders a clip of arms only imposes (its ``columns``), each as (its feature columns, (n, 4) its rotation
    in the body frame) from the clip's (n, D) ``features``; [] when the clip imposes the torso chain too, or its
    features are not the canonical layout."""
    if columns.shape[0] != FEATURE_DIM or columns[chain_columns()].any():
        return []
    chain = chain_rotation(features)  # (n, 4)
    found = []
    for joint in ARM_ROOTS:
        cols = joint_columns(joint)
        if columns[cols].all():
            found.append((cols, quat_mul(chain, quat_from_6d(features[:, cols].astype(np.float64)))))
    return found


def reattach(target: np.ndarray, decoded: np.ndarray, shoulders: list[tuple[list[int], np.ndarray]]) -> np.ndarray:
    """(d, D) pose target with each shoulder's local rotation recomputed under the ``decoded`` (d, D) torso, so that
    its body-frame rotation is the clip's."""
    if not shoulders:
        return target
    target = target.copy()
    inverse = quat_conj(chain_rotation(decoded))  # (d, 4)
    for cols, body_frame in shoulders:
        target[:, cols] = quat_to_6d(quat_mul(inverse, body_frame)).astype(target.dtype)
    return target
