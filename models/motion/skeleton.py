"""The canonical humanoid skeleton (Unity ``HumanBodyBones`` body set) and forward kinematics.

Frame (docs/architecture.md, "Conventions"): right-handed, Y-up, the character faces +Z (its left is +X), metres,
quaternions XYZW, identity local rotation = T-pose. Default rest offsets have ZeroEGGS
proportions (take 067 skeleton; intermediate joints merged, left/right averaged).

Two skeletons: :data:`CANONICAL` (22 body joints) is what the model generates and what motion
files are retargeted to; :data:`CANONICAL_WITH_HANDS` (52 joints) is what the live session sends:
the same 22 joints in the same order, then 15 finger joints per hand (Unity names such as
``LeftThumbProximal``, ``RightLittleDistal``), left hand first. In the T-pose the fingers lie
straight along the arm, palms down (−Y), thumbs pointing forward (+Z) and outward.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gesturecast.models.motion.rotations import quat_mul, quat_rotate

# name, parent name, rest offset from the parent in metres
_CANONICAL_TABLE: tuple[tuple[str, str | None, tuple[float, float, float]], ...] = (
    ("Hips", None, (0.0, 0.870359, 0.0)),
    ("Spine", "Hips", (0.0, 0.088142, -0.020801)),
    ("Chest", "Spine", (0.0, 0.088441, 0.0)),
    ("UpperChest", "Chest", (0.0, 0.234290, 0.0)),  # ZeroEGGS Spine2 + Spine3
    ("Neck", "UpperChest", (0.0, 0.176583, 0.0)),
    ("Head", "Neck", (0.0, 0.102030, 0.0)),  # ZeroEGGS Neck1 + Head
    ("LeftShoulder", "UpperChest", (0.026254, 0.111752, 0.0)),
    ("LeftUpperArm", "LeftShoulder", (0.106242, 0.0, 0.0)),
    ("LeftLowerArm", "LeftUpperArm", (0.291766, 0.0, 0.0)),
    ("LeftHand", "LeftLowerArm", (0.242869, 0.0, 0.0)),
    ("RightShoulder", "UpperChest", (-0.026254, 0.111752, 0.0)),
    ("RightUpperArm", "RightShoulder", (-0.106242, 0.0, 0.0)),
    ("RightLowerArm", "RightUpperArm", (-0.291766, 0.0, 0.0)),
    ("RightHand", "RightLowerArm", (-0.242869, 0.0, 0.0)),
    ("LeftUpperLeg", "Hips", (0.113028, 0.0, 0.0)),
    ("LeftLowerLeg", "LeftUpperLeg", (0.0, -0.382003, 0.0)),
    ("LeftFoot", "LeftLowerLeg", (0.0, -0.399009, 0.0)),
    ("LeftToes", "LeftFoot", (0.0, 0.0, 0.152616)),
    ("RightUpperLeg", "Hips", (-0.113028, 0.0, 0.0)),
    ("RightLowerLeg", "RightUpperLeg", (0.0, -0.382003, 0.0)),
    ("RightFoot", "RightLowerLeg", (0.0, -0.399009, 0.0)),
    ("RightToes", "RightFoot", (0.0, 0.0, 0.152616)),
)

# The five fingers of the left hand: knuckle offset from LeftHand, bone direction, segment lengths
# (proximal→intermediate, intermediate→distal, distal→tip), metres. The right hand mirrors X.
_FINGER_TABLE: tuple[tuple[str, tuple[float, float, float], tuple[float, float, float],
                           tuple[float, float, float]], ...] = (
    ("Thumb", (0.020, -0.012, 0.022), (0.70, -0.20, 0.70), (0.035, 0.030, 0.027)),
    ("Index", (0.090, 0.004, 0.028), (1.0, 0.0, 0.0), (0.040, 0.024, 0.022)),
    ("Middle", (0.094, 0.004, 0.007), (1.0, 0.0, 0.0), (0.045, 0.027, 0.024)),
    ("Ring", (0.088, 0.002, -0.013), (1.0, 0.0, 0.0), (0.041, 0.026, 0.023)),
    ("Little", (0.080, -0.002, -0.031), (1.0, 0.0, 0.0), (0.032, 0.019, 0.020)),
)
FINGERS = tuple(row[0] for row in _FINGER_TABLE)
FINGER_SEGMENTS = ("Proximal", "Intermediate", "Distal")
SIDES = ("Left", "Right")
_MIRROR_X = np.array([-1.0, 1.0, 1.0])


def _finger_rows(side: str) -> tuple[list[tuple[str, str | None, tuple[float, ...]]], dict[str, tuple[float, ...]]]:
    """Skeleton rows (name, parent, offset) of one hand's 15 finger joints, and their fingertip end sites."""
    mirror = _MIRROR_X if side == "Right" else np.ones(3)
    rows: list[tuple[str, str | None, tuple[float, ...]]] = []
    tips: dict[str, tuple[float, ...]] = {}
    for finger, knuckle, direction, lengths in _FINGER_TABLE:
        unit = np.asarray(direction) / np.linalg.norm(direction)  # (3,)
        offsets = [np.asarray(knuckle)] + [length * unit for length in lengths[:-1]]  # 3 × (3,)
        parent = f"{side}Hand"
        for segment, offset in zip(FINGER_SEGMENTS, offsets, strict=True):
            name = f"{side}{finger}{segment}"
            rows.append((name, parent, tuple(float(v) for v in offset * mirror)))
            parent = name
        tips[parent] = tuple(float(v) for v in lengths[-1] * unit * mirror)
    return rows, tips


def finger_joint_names(side: str) -> tuple[str, ...]:
    """The 15 finger joints of one hand (``side`` "Left" or "Right"), finger by finger, proximal first."""
    return tuple(f"{side}{finger}{segment}" for finger in FINGERS for segment in FINGER_SEGMENTS)


# Bone tips for drawing and BVH end sites (offset from the joint, metres).
END_SITES: dict[str, tuple[float, float, float]] = {
    "Head": (0.0, 0.116551, 0.0),
    "LeftHand": (0.09, 0.0, 0.0),
    "RightHand": (-0.09, 0.0, 0.0),
    "LeftToes": (0.0, 0.0, 0.074553),
    "RightToes": (0.0, 0.0, 0.074553),
}


@dataclass(frozen=True)
class Skeleton:
    """A joint hierarchy: names, parent indices (-1 for the root), rest offsets (J, 3) in metres.

    Parents always come before their children, so a single forward pass does FK.
    """

    names: tuple[str, ...]
    parents: tuple[int, ...]
    offsets: np.ndarray = field(repr=False)

    @property
    def num_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def mirror_indices(self) -> np.ndarray:
        """For each joint, the index of its left/right counterpart (itself for the midline)."""
        swapped = [n.replace("Left", "\0").replace("Right", "Left").replace("\0", "Right") for n in self.names]
        return np.array([self.names.index(n) for n in swapped])

    def depth_first_order(self) -> np.ndarray:
        """Joint indices in depth-first order, children in index order (the order of a BVH hierarchy)."""
        children: list[list[int]] = [[] for _ in self.names]
        for j, parent in enumerate(self.parents):
            if parent >= 0:
                children[parent].append(j)
        order, stack = [], [0]
        while stack:
            joint = stack.pop()
            order.append(joint)
            stack.extend(reversed(children[joint]))
        return np.array(order)

    def forward_kinematics(
        self, local_rotations: np.ndarray, root_position: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Global joint rotations and positions.

        local_rotations: (..., J, 4) XYZW; root_position: (..., 3) metres, the Hips position
        (defaults to the rest offset of the root). Returns (global_rot (..., J, 4),
        positions (..., J, 3)).
        """
        batch = local_rotations.shape[:-2]
        if root_position is None:
            root_position = np.broadcast_to(self.offsets[0], (*batch, 3))
        global_rot = np.empty_like(local_rotations)
        positions = np.empty((*batch, self.num_joints, 3))
        global_rot[..., 0, :] = local_rotations[..., 0, :]
        positions[..., 0, :] = root_position
        for j in range(1, self.num_joints):
            p = self.parents[j]
            global_rot[..., j, :] = quat_mul(global_rot[..., p, :], local_rotations[..., j, :])
            positions[..., j, :] = positions[..., p, :] + quat_rotate(
                global_rot[..., p, :], np.broadcast_to(self.offsets[j], (*batch, 3))
            )
        return global_rot, positions

    def height(self) -> float:
        """Rest-pose height from the lowest joint to the top of the head (metres)."""
        rest = np.zeros((self.num_joints, 4))
        rest[:, 3] = 1.0
        _, pos = self.forward_kinematics(rest)
        top = pos[self.index("Head"), 1] + END_SITES["Head"][1] if "Head" in self.names else pos[:, 1].max()
        return float(top - pos[:, 1].min())


def _build_skeleton(table: tuple[tuple[str, str | None, tuple[float, ...]], ...]) -> Skeleton:
    names = tuple(row[0] for row in table)
    parents = tuple(-1 if row[1] is None else names.index(row[1]) for row in table)
    offsets = np.array([row[2] for row in table], dtype=np.float64)
    return Skeleton(names, parents, offsets)


_HAND_ROWS = {side: _finger_rows(side) for side in SIDES}
FINGERTIPS: dict[str, tuple[float, ...]] = {name: tip for side in SIDES for name, tip in _HAND_ROWS[side][1].items()}

CANONICAL = _build_skeleton(_CANONICAL_TABLE)
CANONICAL_JOINTS = CANONICAL.names
NUM_JOINTS = CANONICAL.num_joints
CANONICAL_WITH_HANDS = _build_skeleton(_CANONICAL_TABLE + tuple(row for side in SIDES for row in _HAND_ROWS[side][0]))
NUM_FINGER_JOINTS = CANONICAL_WITH_HANDS.num_joints - NUM_JOINTS  # 30: 15 per hand
