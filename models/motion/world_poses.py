"""Arms from upper-body world poses: the 9-joint ZeroEGGS format of the zeggs_upper data.

Each frame holds world positions and world rotations of Hips, Spine2, Spine3 (the canonical UpperChest) and
each side's shoulder joint, elbow and wrist (:data:`WORLD_JOINTS`). The rotations' rest frames are not the
canonical T-pose (each bone lies along its local +Y), and the clavicles are absent, so the canonical arms are
rebuilt in three steps:

1. **Rest offset per joint.** For a data joint j the canonical global rotation is ``G_j = Q_j · C_j`` with a
   constant ``C_j``. ``C_j`` is solved as the rotation (Kabsch / Wahba, SVD) that best maps two or three
   direction statistics seen in the joint's canonical frame onto the same statistics seen in its data frame:
   the bone to the next joint, the elbow's hinge axis (the normal of shoulder–elbow–wrist), and for the chest the
   line between the shoulders. The canonical side of each statistic is measured on a **reference**: a full-body
   BVH of the same skeleton (the shared ZeroEGGS take), retargeted as usual. Bone directions are exact; the hinge
   axis and the hand's directions are means over frames, so they assume the two takes use the elbow and wrist
   alike (the same actress here).
2. **Clavicles from positions.** The clavicle is the swing that points it, from where the chest puts its root,
   at the observed shoulder joint. Its twist about its own bone is not observed and is left at zero.
3. **Local rotations** of shoulder, upper arm, lower arm and hand follow as ``G_parent⁻¹ · G_child``.

Every other joint is left at the identity: those columns are masked in training (the take's ``parts`` are the
arms only), never invented. ``measure_world_pose_fit`` checks the whole procedure on the reference itself.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.body_parts import ARM_JOINTS
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.motion import SkeletonMotion, check_clip_header
from gesturecast.models.motion.resample import resample_motion
from gesturecast.models.motion.retarget import retarget_bvh
from gesturecast.models.motion.rotations import (
    quat_between,
    quat_conj,
    quat_from_matrix,
    quat_identity,
    quat_mul,
    quat_normalize,
    quat_rotate,
)
from gesturecast.models.motion.skeleton import CANONICAL, Skeleton

WORLD_POSE_FPS = 60.0  # the format's frame rate (it stores none)
WORLD_JOINTS = ("Hips", "Spine2", "UpperChest", "RightUpperArm", "RightLowerArm", "RightHand", "LeftUpperArm",
                "LeftLowerArm", "LeftHand")
SOLVED_JOINTS = ("UpperChest", "RightUpperArm", "RightLowerArm", "RightHand", "LeftUpperArm", "LeftLowerArm",
                 "LeftHand")
SIDES = ("Left", "Right")
VALUES_PER_JOINT = 7  # px py pz qx qy qz qw
MIN_HINGE_SINE = 0.3  # elbow bent by > 17 deg: below, the hinge normal is mostly noise
UNIT_TOLERANCE = 1e-3
SPINE2_STAND_IN = {"Spine2": "Chest"}  # the canonical skeleton has no Spine2; the solver never reads that joint


@dataclass(frozen=True)
class WorldPoses:
    """Per frame world positions (T, 9, 3) in metres and world rotations (T, 9, 4) XYZW, in :data:`WORLD_JOINTS`."""

    positions: np.ndarray
    rotations: np.ndarray

    def position(self, joint: str) -> np.ndarray:
        return self.positions[:, WORLD_JOINTS.index(joint)]  # (T, 3)

    def rotation(self, joint: str) -> np.ndarray:
        return self.rotations[:, WORLD_JOINTS.index(joint)]  # (T, 4)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def hinge_normals(poses: WorldPoses, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (T, 3) of the shoulder–elbow–wrist plane, and which frames bend enough to define one (T,)."""
    upper = poses.position(f"{side}LowerArm") - poses.position(f"{side}UpperArm")  # (T, 3)
    lower = poses.position(f"{side}Hand") - poses.position(f"{side}LowerArm")  # (T, 3)
    normal = np.cross(_unit(upper), _unit(lower))  # (T, 3), length = sine of the elbow bend
    return _unit(normal), np.linalg.norm(normal, axis=-1) > MIN_HINGE_SINE


def joint_statistics(poses: WorldPoses, joint: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """The world directions (T, 3) that pin ``joint``'s frame, each with the frames (T,) where it is defined."""
    everywhere = np.ones(len(poses.positions), bool)
    if joint == "UpperChest":
        shoulders = {side: poses.position(f"{side}UpperArm") for side in SIDES}
        middle = 0.5 * (shoulders["Left"] + shoulders["Right"]) - poses.position("UpperChest")
        return [(_unit(middle), everywhere), (_unit(shoulders["Left"] - shoulders["Right"]), everywhere)]
    side, bone = ("Left", joint[4:]) if joint.startswith("Left") else ("Right", joint[5:])
    normal, bent = hinge_normals(poses, side)
    forearm = _unit(poses.position(f"{side}Hand") - poses.position(f"{side}LowerArm"))
    if bone == "UpperArm":
        return [(_unit(poses.position(f"{side}LowerArm") - poses.position(joint)), everywhere), (normal, bent)]
    return [(forearm, everywhere), (normal, bent)]  # LowerArm: its bone; Hand: the forearm and hinge it hangs on


def local_means(rotations: np.ndarray, statistics: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """Mean unit direction (K, 3) of each statistic in the joint's own frame (rotations (T, 4))."""
    means = []
    for direction, valid in statistics:
        local = quat_rotate(quat_conj(rotations[valid]), direction[valid])  # (T_valid, 3)
        means.append(_unit(local.mean(axis=0)))
    return np.stack(means)


def kabsch(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The rotation (4,) R minimising Σ |R · source_k − target_k|² over directions (K, 3) (Wahba's problem)."""
    covariance = target.T @ source  # (3, 3)
    u, _, vt = np.linalg.svd(covariance)
    fix = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    return quat_from_matrix(u @ fix @ vt)


@dataclass(frozen=True)
class ReferenceStatistics:
    """What a full-body reference take tells about the canonical frames (see the module docstring)."""

    canonical_means: dict[str, np.ndarray]  # joint -> (K, 3) statistic means in its canonical frame
    skeleton: Skeleton  # the canonical hierarchy with the reference's bone lengths


def world_poses_of(motion: SkeletonMotion, skeleton: Skeleton) -> WorldPoses:
    """The 9 world joints of a canonical motion (as the format would store them with canonical rest frames)."""
    rotations, positions = skeleton.forward_kinematics(motion.rotations, motion.root_position)  # (T, J, 4), (T, J, 3)
    columns = [skeleton.index(SPINE2_STAND_IN.get(name, name)) for name in WORLD_JOINTS]
    return WorldPoses(positions[:, columns], rotations[:, columns])  # (T, 9, 3), (T, 9, 4)


def reference_statistics(motion: SkeletonMotion, skeleton: Skeleton) -> ReferenceStatistics:
    poses = world_poses_of(motion, skeleton)
    means = {joint: local_means(poses.rotation(joint), joint_statistics(poses, joint)) for joint in SOLVED_JOINTS}
    return ReferenceStatistics(means, skeleton)


@functools.lru_cache(maxsize=4)
def bvh_reference(path: Path) -> ReferenceStatistics:
    """Reference statistics of a full-body BVH of the same skeleton (read once per path)."""
    retargeted = retarget_bvh(read_bvh(path), source=str(path))
    return reference_statistics(retargeted.motion, retargeted.source_skeleton)


def canonical_globals(poses: WorldPoses, reference: ReferenceStatistics) -> dict[str, np.ndarray]:
    """Canonical global rotations (T, 4) of the solved joints: G_j = Q_j · C_j (step 1)."""
    globals_ = {}
    for joint in SOLVED_JOINTS:
        data_means = local_means(poses.rotation(joint), joint_statistics(poses, joint))  # (K, 3)
        rest_offset = kabsch(reference.canonical_means[joint], data_means)  # (4,) canonical frame → data frame
        rotation = poses.rotation(joint)
        globals_[joint] = quat_normalize(quat_mul(rotation, np.broadcast_to(rest_offset, rotation.shape)))
    return globals_


def clavicle_global(poses: WorldPoses, chest: np.ndarray, side: str, skeleton: Skeleton) -> np.ndarray:
    """Global rotation (T, 4) of ``{side}Shoulder``: the chest's, swung so the clavicle reaches the shoulder joint."""
    root_offset = np.broadcast_to(skeleton.offsets[skeleton.index(f"{side}Shoulder")], (len(chest), 3))
    root = poses.position("UpperChest") + quat_rotate(chest, root_offset)  # (T, 3)
    observed = quat_rotate(quat_conj(chest), poses.position(f"{side}UpperArm") - root)  # (T, 3) in the chest frame
    rest = np.broadcast_to(skeleton.offsets[skeleton.index(f"{side}UpperArm")], observed.shape)
    return quat_mul(chest, quat_between(rest, observed))


def arm_local_rotations(poses: WorldPoses, reference: ReferenceStatistics) -> np.ndarray:
    """Canonical local rotations (T, J, 4): the arms solved, every other joint the identity."""
    globals_ = canonical_globals(poses, reference)
    for side in SIDES:
        globals_[f"{side}Shoulder"] = clavicle_global(poses, globals_["UpperChest"], side, reference.skeleton)
    local = quat_identity((len(poses.positions), CANONICAL.num_joints))  # (T, J, 4)
    for joint in ARM_JOINTS:
        parent = CANONICAL.names[CANONICAL.parents[CANONICAL.index(joint)]]
        local[:, CANONICAL.index(joint)] = quat_mul(quat_conj(globals_[parent]), globals_[joint])
    return quat_normalize(local)


def read_world_poses(path: Path) -> WorldPoses:
    """The ``(T, 9, 7)`` array of a world-pose ``.npy``, checked; a UserError names what is wrong."""
    try:
        values = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as error:
        raise UserError(f"cannot read {path} as a world-pose .npy: {error}") from None
    expected = (len(WORLD_JOINTS), VALUES_PER_JOINT)
    if values.ndim != 3 or values.shape[1:] != expected:
        raise UserError(f"{path}: expected world poses of shape (frames, {expected[0]}, {expected[1]}), "
                        f"got {values.shape}")
    check_clip_header(WORLD_POSE_FPS, len(values), str(path))
    values = values.astype(np.float64)
    if not np.isfinite(values).all():
        raise UserError(f"{path}: world poses hold NaN or infinite values")
    norms = np.linalg.norm(values[..., 3:], axis=-1)
    if np.abs(norms - 1.0).max() > UNIT_TOLERANCE:
        raise UserError(f"{path}: rotations are not unit quaternions (norm {norms.min():.3f}–{norms.max():.3f})")
    return WorldPoses(values[..., :3], quat_normalize(values[..., 3:]))


def load_world_pose_motion(path: Path, reference_bvh: Path) -> SkeletonMotion:
    """A world-pose take as canonical SkeletonMotion at 30 fps: arms solved against ``reference_bvh``, the rest
    identity."""
    poses = read_world_poses(path)
    reference = bvh_reference(Path(reference_bvh))
    root = poses.position("Hips")  # (T, 3)
    return resample_motion(SkeletonMotion(arm_local_rotations(poses, reference), root, WORLD_POSE_FPS))


def angle_errors_deg(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Angles (...) in degrees between two sets of unit quaternions (..., 4)."""
    dot = np.abs(np.sum(estimate * truth, axis=-1))
    return np.degrees(2.0 * np.arccos(np.clip(dot, -1.0, 1.0)))


def measure_world_pose_fit(motion: SkeletonMotion, skeleton: Skeleton, seed: int = 0) -> dict[str, float]:
    """Median arm-joint error (°) of the whole procedure on a full-body take whose truth is known.

    The first half of ``motion`` is the reference; the second half is turned into world poses whose rotations
    carry random rest offsets (the solver must find them), solved, and compared with its own local rotations.
    """
    half = motion.num_frames // 2
    first, second = (SkeletonMotion(motion.rotations[s], motion.root_position[s], motion.fps)
                     for s in (slice(0, half), slice(half, None)))
    poses = world_poses_of(second, skeleton)
    offsets = quat_normalize(np.random.default_rng(seed).normal(size=(len(WORLD_JOINTS), 4)))  # (9, 4)
    scrambled = WorldPoses(poses.positions, quat_mul(poses.rotations, np.broadcast_to(offsets, poses.rotations.shape)))
    solved = arm_local_rotations(scrambled, reference_statistics(first, skeleton))
    return {joint: float(np.median(angle_errors_deg(solved[:, CANONICAL.index(joint)],
                                                    second.rotations[:, CANONICAL.index(joint)])))
            for joint in ARM_JOINTS}
