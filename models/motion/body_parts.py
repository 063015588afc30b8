"""The body-part partition of GestureDiffuCLIP §6.3: which motion-feature columns each part owns.

Three parts, chosen for speech gestures:

- ``arms``: both shoulders, upper arms, forearms and hands. Nearly all co-speech gesture lives here,
  and it is the part a user most wants to restyle ("happy arms").
- ``torso``: spine, chest, upper chest, neck and head. Posture (a bowed "old" back, a raised "proud"
  chest) and head nods; it carries the arms, so its style is read even when the arms are calm.
- ``legs``: the root channels (height, planar velocity, yaw rate), the hips rotation and both legs.
  They move together (stance, weight shift, steps) and are the part upper-body-only recordings lack.

Every column of the feature vector (:mod:`motion_features`) belongs to exactly one part, so the
parts' features put back together are the whole body's. The fingers are not generated (they come
from the live session's procedural hands, realtime/pose/hands.py), so they belong to no part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.motion_features import ROOT_DIM, ROTATION_6D_DIM
from gesturecast.models.motion.skeleton import CANONICAL

ARM_JOINTS = tuple(f"{side}{bone}" for side in ("Left", "Right") for bone in ("Shoulder", "UpperArm", "LowerArm",
                                                                               "Hand"))
TORSO_JOINTS = ("Spine", "Chest", "UpperChest", "Neck", "Head")
LEG_JOINTS = ("Hips",) + tuple(f"{side}{bone}" for side in ("Left", "Right") for bone in ("UpperLeg", "LowerLeg",
                                                                                          "Foot", "Toes"))
PART_JOINTS = {"arms": ARM_JOINTS, "torso": TORSO_JOINTS, "legs": LEG_JOINTS}
PART_NAMES = tuple(PART_JOINTS)
ROOT_PART = "legs"  # the part that owns the root channels


@dataclass(frozen=True)
class BodyPart:
    """A named set of canonical joints and the feature columns (ascending) that describe them."""

    name: str
    joints: tuple[str, ...]
    columns: tuple[int, ...]

    @property
    def feature_dim(self) -> int:
        return len(self.columns)


def joint_columns(joint: str) -> list[int]:
    """The 6 feature columns of a canonical joint's rotation (the hips' sit right after the root channels)."""
    start = ROOT_DIM + ROTATION_6D_DIM * CANONICAL.index(joint)
    return list(range(start, start + ROTATION_6D_DIM))


def body_part(name: str) -> BodyPart:
    if name not in PART_JOINTS:
        raise ValueError(f"unknown body part {name!r}; parts: {', '.join(PART_NAMES)}")
    joints = PART_JOINTS[name]
    columns = (list(range(ROOT_DIM)) if name == ROOT_PART else []) + [c for j in joints for c in joint_columns(j)]
    return BodyPart(name, joints, tuple(sorted(columns)))


def holds_every_part(parts: tuple[str, ...] | list[str]) -> bool:
    """Whether a take's reliable ``parts`` are the whole body (every part, in canonical order)."""
    return tuple(parts) == PART_NAMES


def body_parts(names: tuple[str, ...] = PART_NAMES) -> tuple[BodyPart, ...]:
    """The parts, checked to cover every canonical feature column exactly once."""
    parts = tuple(body_part(name) for name in names)
    covered = np.sort(np.concatenate([part.columns for part in parts]))
    expected = np.arange(ROOT_DIM + ROTATION_6D_DIM * CANONICAL.num_joints)
    if not np.array_equal(covered, expected):
        raise ValueError(f"parts {names} do not cover each motion-feature column exactly once")
    return parts
