"""Joint-name maps from source skeletons onto the canonical skeleton.

A map assigns each canonical joint a *chain* of source joints. The first joint of the chain
gives the canonical joint's position; the last one drives its rotation (intermediate source
joints such as ZeroEGGS ``Spine2`` or ``Neck1`` are merged: their rotations are composed into
the last joint's global rotation). An empty chain means the source has no such joint: the
canonical joint then keeps an identity local rotation (it follows its parent).

Built-in maps: ZeroEGGS, Mixamo, CMU, Bandai Namco, SMPL-X and the canonical skeleton itself. :func:`detect_joint_map`
picks the most specific built-in map whose joints are all present; :func:`load_joint_map`
reads a user JSON map ``{"Hips": ["pelvis"], "Spine": ["spine_01"], ...}``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.input_files import read_bounded
from gesturecast.models.motion.skeleton import CANONICAL_JOINTS

NAMESPACE_SEPARATOR = ":"  # Mixamo exports name joints "mixamorig:Hips"
# a built-in map is offered as the likely layout when at least this share of its joints is present
NEAR_MATCH_FRACTION = 0.5
MAX_JOINT_MAP_BYTES = 1 << 20  # a joint map is a few hundred joint names: 1 MiB is far more


@dataclass(frozen=True)
class JointMap:
    """Canonical joint name -> chain of source joint names (empty tuple: no source joint)."""

    name: str
    chains: dict[str, tuple[str, ...]]

    def source_joints(self) -> list[str]:
        return [source for chain in self.chains.values() for source in chain]

    def missing_joints(self, source_names: list[str]) -> list[str]:
        present = set(source_names)
        return [source for source in self.source_joints() if source not in present]

    def chain(self, canonical: str) -> tuple[str, ...]:
        return self.chains[canonical]


def _sided(body: dict[str, list[str]], limb: dict[str, list[str]], left: str, right: str) -> dict[str, tuple[str, ...]]:
    """Build a full chain table from the midline chains and the limb chains written with ``{side}``."""
    chains = {name: tuple(chain) for name, chain in body.items()}
    for canonical_side, source_side in (("Left", left), ("Right", right)):
        for name, chain in limb.items():
            chains[canonical_side + name] = tuple(s.format(side=source_side) for s in chain)
    return {name: chains[name] for name in CANONICAL_JOINTS}


# the Mixamo / ZeroEGGS / CMU limb naming (LeftArm = upper arm, LeftForeArm = lower arm, ...)
_LEFT_RIGHT_LIMBS = {
    "Shoulder": ["{side}Shoulder"],
    "UpperArm": ["{side}Arm"],
    "LowerArm": ["{side}ForeArm"],
    "Hand": ["{side}Hand"],
    "UpperLeg": ["{side}UpLeg"],
    "LowerLeg": ["{side}Leg"],
    "Foot": ["{side}Foot"],
    "Toes": ["{side}ToeBase"],
}

ZEROEGGS = JointMap(
    "ZeroEGGS",
    _sided(
        {"Hips": ["Hips"], "Spine": ["Spine"], "Chest": ["Spine1", "Spine2"], "UpperChest": ["Spine3"],
         "Neck": ["Neck", "Neck1"], "Head": ["Head"]},
        _LEFT_RIGHT_LIMBS, "Left", "Right",
    ),
)

MIXAMO = JointMap(
    "Mixamo",
    _sided(
        {"Hips": ["Hips"], "Spine": ["Spine"], "Chest": ["Spine1"], "UpperChest": ["Spine2"],
         "Neck": ["Neck"], "Head": ["Head"]},
        _LEFT_RIGHT_LIMBS, "Left", "Right",
    ),
)

# CMU (cgspeed BVH conversion): LowerBack sits on the hips, shoulders hang off Spine1, and
# LHipJoint/RHipJoint lie between Hips and the thighs (their rotations reach the thighs anyway).
CMU = JointMap(
    "CMU",
    _sided(
        {"Hips": ["Hips"], "Spine": ["LowerBack"], "Chest": ["Spine"], "UpperChest": ["Spine1"],
         "Neck": ["Neck", "Neck1"], "Head": ["Head"]},
        _LEFT_RIGHT_LIMBS, "Left", "Right",
    ),
)

BANDAI_NAMCO = JointMap(
    "Bandai Namco",
    _sided(
        {"Hips": ["Hips"], "Spine": ["Spine"], "Chest": ["Chest"], "UpperChest": [], "Neck": ["Neck"],
         "Head": ["Head"]},
        {"Shoulder": ["Shoulder_{side}"], "UpperArm": ["UpperArm_{side}"], "LowerArm": ["LowerArm_{side}"],
         "Hand": ["Hand_{side}"], "UpperLeg": ["UpperLeg_{side}"], "LowerLeg": ["LowerLeg_{side}"],
         "Foot": ["Foot_{side}"], "Toes": ["Toes_{side}"]},
        "L", "R",
    ),
)

# SMPL-X body joints, in the order of the 55 axis-angle triples in ``poses`` (BEAT2, AMASS, TalkSHOW)
SMPLX_JOINTS: tuple[str, ...] = (
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2", "left_ankle",
    "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar", "right_collar", "head",
    "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "jaw",
    "left_eye", "right_eye",
    *(f"{side}_{finger}{k}" for side in ("left", "right")
      for finger in ("index", "middle", "pinky", "ring", "thumb") for k in (1, 2, 3)),
)
_SMPLX_BODY_PARENTS = (-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 15, 15, 15)
_SMPLX_FINGER_JOINTS = 3
_SMPLX_FINGERS_PER_HAND = 5
_SMPLX_WRISTS = (20, 21)


def _smplx_parents() -> tuple[int, ...]:
    parents = list(_SMPLX_BODY_PARENTS)
    for wrist in _SMPLX_WRISTS:
        for _ in range(_SMPLX_FINGERS_PER_HAND):
            first = len(parents)
            parents.extend([wrist] + [first + k for k in range(_SMPLX_FINGER_JOINTS - 1)])
    return tuple(parents)


SMPLX_PARENTS = _smplx_parents()

SMPLX = JointMap(
    "SMPL-X",
    _sided(
        {"Hips": ["pelvis"], "Spine": ["spine1"], "Chest": ["spine2"], "UpperChest": ["spine3"], "Neck": ["neck"],
         "Head": ["head"]},
        {"Shoulder": ["{side}_collar"], "UpperArm": ["{side}_shoulder"], "LowerArm": ["{side}_elbow"],
         "Hand": ["{side}_wrist"], "UpperLeg": ["{side}_hip"], "LowerLeg": ["{side}_knee"],
         "Foot": ["{side}_ankle"], "Toes": ["{side}_foot"]},
        "left", "right",
    ),
)

# this project's own BVH exports (motion_to_bvh, the BVH recorder)
GESTURECAST = JointMap("gesturecast canonical", {name: (name,) for name in CANONICAL_JOINTS})

BUILTIN_BVH_MAPS: tuple[JointMap, ...] = (ZEROEGGS, MIXAMO, CMU, BANDAI_NAMCO, GESTURECAST)


def strip_namespace(name: str) -> str:
    """``mixamorig:LeftArm`` -> ``LeftArm``."""
    return name.rsplit(NAMESPACE_SEPARATOR, 1)[-1]


def detect_joint_map(source_names: list[str], source: str = "motion file") -> JointMap:
    """The most specific built-in map whose source joints are all present (names without namespace).

    Raises UserError naming the missing joints of the closest built-in layout, or asking for a
    user map file when no layout is close.
    """
    names = [strip_namespace(n) for n in source_names]
    complete = [m for m in BUILTIN_BVH_MAPS if not m.missing_joints(names)]
    if complete:
        return max(complete, key=lambda m: len(set(m.source_joints())))
    closest = min(BUILTIN_BVH_MAPS, key=lambda m: len(m.missing_joints(names)) / len(m.source_joints()))
    missing = closest.missing_joints(names)
    if len(missing) <= (1.0 - NEAR_MATCH_FRACTION) * len(closest.source_joints()):
        raise UserError(f"{source}: looks like a {closest.name} skeleton but lacks joints {', '.join(missing)}; "
                        "pass a joint map file for this skeleton (see docs/retargeting.md)")
    raise UserError(f"{source}: unknown skeleton layout (joints such as {', '.join(source_names[:4])}); "
                    "pass a joint map file (see docs/retargeting.md)")


def load_joint_map(path: str | Path) -> JointMap:
    """Read a user map: JSON object, canonical joint name -> list of source joint names (or one name)."""
    path = Path(path)
    try:
        raw = json.loads(read_bounded(path, MAX_JOINT_MAP_BYTES, "joint map").decode("utf-8"))
    except UnicodeDecodeError as error:
        raise UserError(f"joint map {path} is not UTF-8 text ({error})") from None
    except json.JSONDecodeError as error:
        raise UserError(f"joint map {path} is not valid JSON: {error.msg} (line {error.lineno})") from None
    except (ValueError, RecursionError) as error:  # an integer of thousands of digits, nesting thousands deep
        raise UserError(f"joint map {path} is not valid JSON ({type(error).__name__})") from None
    if not isinstance(raw, dict):
        raise UserError(f"joint map {path} must be a JSON object: canonical joint name -> source joint names")
    unknown = [k for k in raw if k not in CANONICAL_JOINTS]
    if unknown:
        raise UserError(f"joint map {path}: unknown canonical joints {', '.join(unknown)} "
                        f"(expected names from {', '.join(CANONICAL_JOINTS)})")
    chains: dict[str, tuple[str, ...]] = {}
    for name in CANONICAL_JOINTS:
        value = raw.get(name, [])
        chain = [value] if isinstance(value, str) else value
        if not isinstance(chain, list) or not all(isinstance(s, str) for s in chain):
            raise UserError(f"joint map {path}: '{name}' must map to a joint name or a list of joint names")
        chains[name] = tuple(chain)
    if not chains[CANONICAL_JOINTS[0]]:
        raise UserError(f"joint map {path}: '{CANONICAL_JOINTS[0]}' must be mapped")
    return JointMap(f"user map {path.name}", chains)


def check_joints_present(joint_map: JointMap, source_names: list[str], source: str) -> None:
    """UserError listing the mapped source joints that ``source_names`` lacks."""
    missing = joint_map.missing_joints(source_names)
    if missing:
        raise UserError(f"{source}: the {joint_map.name} joint map needs joints missing from the file: "
                        f"{', '.join(missing)}")
