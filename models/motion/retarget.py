"""Loading mocap files of any supported skeleton as canonical :class:`SkeletonMotion` at 30 fps.

``.bvh``: a built-in joint map is detected from the joint names (ZeroEGGS, Mixamo, CMU,
Bandai Namco), or a user JSON map is given; the source's T-pose is solved
(:mod:`.rest_alignment`) so that it maps to identity. ``.npz``: SMPL-X axis-angle ``poses``
(T, 165) and ``trans`` (T, 3), as in BEAT2 / AMASS. Root positions are converted to metres and
scaled by the canonical hip height over the source's (leg length, so the feet stay on the floor).
Facing is left as recorded.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import BvhData, read_bvh, write_bvh
from gesturecast.models.motion.canonical_bvh import BVH_UNITS_PER_METRE, canonical_bvh_data
from gesturecast.models.motion.joint_maps import (
    SMPLX,
    SMPLX_JOINTS,
    SMPLX_PARENTS,
    JointMap,
    check_joints_present,
    detect_joint_map,
    load_joint_map,
    strip_namespace,
)
from gesturecast.models.motion.motion import (
    MOTION_FPS,
    SkeletonMotion,
    check_clip_header,
    check_file_size,
    check_root_path,
    check_rotations,
)
from gesturecast.models.motion.resample import resample_motion
from gesturecast.models.motion.rest_alignment import (
    MappedSkeleton,
    SourceSkeleton,
    hip_height,
    joint_tips,
    solve_tpose,
    tpose_hip_height,
    tpose_positions,
)
from gesturecast.models.motion.rotations import (
    quat_between,
    quat_conj,
    quat_from_axis_angle,
    quat_identity,
    quat_mul,
    quat_normalize,
    quat_rotate,
)
from gesturecast.models.motion.skeleton import CANONICAL, CANONICAL_WITH_HANDS, Skeleton

logger = logging.getLogger(__name__)

# SMPL-X: no body model ships here, so its height is taken as a nominal adult's, and the root
# height is set by putting the clip's feet on the floor (FLOOR_PERCENTILE of the lowest joint)
SMPLX_NOMINAL_HEIGHT_M = 1.70
FLOOR_PERCENTILE = 5.0
SMPLX_AXIS_ANGLE_DIM = 3 * len(SMPLX_JOINTS)
MIN_BONE_LENGTH = 1e-9  # source units; shorter bones carry no direction
MAX_POSE_RADIANS = 1e4  # an SMPL-X axis-angle value beyond this (1,600 turns) is no pose; 1e308 overflowed the angle


@dataclass
class Retargeted:
    """A retargeted clip at the source frame rate, with what the retargeting found.

    source_skeleton: the canonical hierarchy with the source's bone lengths (metres, after
    scaling): the retargeted rotations on it reproduce the source's joint positions.
    scale: source length units -> canonical metres.
    """

    motion: SkeletonMotion
    joint_map: JointMap
    scale: float
    source_skeleton: Skeleton


def source_forward_kinematics(
    parents: np.ndarray, local_rotations: np.ndarray, local_translations: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray | None]:
    """Global rotations (T, J, 4) and, given translations (T, J, 3), global positions (T, J, 3)."""
    global_rot = np.empty_like(local_rotations)
    positions = None if local_translations is None else np.empty_like(local_translations)
    for j, p in enumerate(parents):
        if p < 0:
            global_rot[:, j] = local_rotations[:, j]
            if positions is not None:
                positions[:, j] = local_translations[:, j]
            continue
        global_rot[:, j] = quat_mul(global_rot[:, p], local_rotations[:, j])
        if positions is not None:
            positions[:, j] = positions[:, p] + quat_rotate(global_rot[:, p], local_translations[:, j])
    return global_rot, positions


def _merged_chain_correction(
    mapped: MappedSkeleton, c: int, tpose: np.ndarray, global_c: np.ndarray, source_positions: np.ndarray
) -> np.ndarray:
    """Swing (T, 4) that points a merged chain's bone (e.g. Spine1 + Spine2) at the source's next joint.

    The driver's rotation ignores how the chain's intermediate joints bend; this restores the
    bone direction from the source positions, keeping the driver's twist.
    """
    k = mapped.primary_child(c)
    if k < 0 or mapped.first[c] == mapped.driver[c]:
        return quat_identity((len(global_c),))
    rest_bone = quat_rotate(tpose[c], mapped.source.vector(mapped.first[c], mapped.first[k]))
    if np.linalg.norm(rest_bone) < MIN_BONE_LENGTH:
        return quat_identity((len(global_c),))
    current = quat_rotate(global_c, np.broadcast_to(rest_bone, global_c[..., :3].shape))  # (T, 3)
    actual = source_positions[:, mapped.first[k]] - source_positions[:, mapped.first[c]]  # (T, 3)
    return quat_between(current, actual)


def canonical_local_rotations(
    mapped: MappedSkeleton, source_global: np.ndarray, tpose: np.ndarray, source_positions: np.ndarray | None = None
) -> np.ndarray:
    """Canonical local rotations (T, J, 4): G_c = G_driver · T⁻¹, local = G_parent⁻¹ · G_c.

    With source_positions (T, J_source, 3), merged chains are swung onto the source's bone direction.
    """
    num_frames = source_global.shape[0]
    canonical_global = quat_identity((num_frames, CANONICAL.num_joints))  # (T, J, 4)
    local = quat_identity((num_frames, CANONICAL.num_joints))  # (T, J, 4)
    for c, p in enumerate(CANONICAL.parents):
        d = mapped.driver[c]
        if d < 0:
            canonical_global[:, c] = canonical_global[:, p]
            continue
        global_c = quat_mul(source_global[:, d], quat_conj(tpose[c]))
        if source_positions is not None:
            global_c = quat_mul(_merged_chain_correction(mapped, c, tpose, global_c, source_positions), global_c)
        canonical_global[:, c] = global_c
        parent_global = canonical_global[:, p] if p >= 0 else quat_identity((num_frames,))
        local[:, c] = quat_mul(quat_conj(parent_global), global_c)
    return quat_normalize(local)


def _source_skeleton(data: BvhData) -> SourceSkeleton:
    return SourceSkeleton(
        names=[strip_namespace(n) for n in data.names],
        parents=data.parents,
        offsets=data.offsets,
        tips=joint_tips(data.parents, data.offsets, data.end_sites),
    )


def _proportioned_skeleton(mapped: MappedSkeleton, tpose: np.ndarray, scale: float) -> Skeleton:
    positions = tpose_positions(mapped, tpose) * scale  # (J, 3) metres, Hips at 0
    offsets = np.array([positions[c] - positions[p] if p >= 0 else CANONICAL.offsets[0]
                        for c, p in enumerate(CANONICAL.parents)])
    return Skeleton(CANONICAL.names, CANONICAL.parents, offsets)


def retarget_bvh(data: BvhData, joint_map: JointMap | None = None, source: str = "BVH") -> Retargeted:
    """Retarget parsed BVH data onto the canonical skeleton (at the file's frame rate)."""
    skeleton = _source_skeleton(data)
    joint_map = joint_map or detect_joint_map(data.names, source)
    check_joints_present(joint_map, skeleton.names, source)
    mapped = MappedSkeleton.build(skeleton, joint_map)
    source_global, source_positions = source_forward_kinematics(
        data.parents, data.local_rotations(), data.local_translations()
    )
    tpose = solve_tpose(mapped, source_global)
    scale = canonical_hip_height() / _source_hip_height(mapped, tpose, source)
    logger.debug("%s: %s skeleton, scale %.5f to canonical metres", source, joint_map.name, scale)
    rotations = canonical_local_rotations(mapped, source_global, tpose, source_positions)
    root = source_positions[:, mapped.first[0]] * scale  # (T, 3)
    check_root_path(root, source)
    motion = SkeletonMotion(rotations, root, data.fps)
    return Retargeted(motion, joint_map, scale, _proportioned_skeleton(mapped, tpose, scale))


def _source_hip_height(mapped: MappedSkeleton, tpose: np.ndarray, source: str) -> float:
    """The source's T-pose hip height (its unit of scale); UserError naming the leg joints when it is zero
    (all-zero OFFSETs: nothing to scale the clip by)."""
    height = tpose_hip_height(mapped, tpose)
    if height > MIN_BONE_LENGTH:
        return height
    legs = [c for c, name in enumerate(CANONICAL.names) if name.endswith(("Leg", "Foot", "Toes"))]
    flat = [mapped.source.names[mapped.first[c]] for c in legs if mapped.driver[c] >= 0
            and np.linalg.norm(mapped.source.vector(mapped.first[mapped.mapped_parent(c)], mapped.first[c]))
            <= MIN_BONE_LENGTH]
    where = f"zero OFFSET on {', '.join(flat)}" if flat else "no joint below the Hips"
    raise UserError(f"{source}: the legs have no length in the rest pose ({where}); cannot scale the clip")


def canonical_hip_height() -> float:
    """Rest height of the canonical Hips above its lowest joint (metres)."""
    return hip_height(CANONICAL.forward_kinematics(quat_identity((CANONICAL.num_joints,)))[1])


def _ground_root_height(rotations: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Shift the root vertically so the clip's feet stand on the canonical rest floor."""
    _, positions = CANONICAL.forward_kinematics(rotations, root)  # (T, J, 3)
    floor = np.percentile(positions[..., 1].min(axis=1), FLOOR_PERCENTILE)
    _, rest = CANONICAL.forward_kinematics(quat_identity((CANONICAL.num_joints,)))
    return root + np.array([0.0, rest[:, 1].min() - floor, 0.0])


def retarget_smplx(poses: np.ndarray, trans: np.ndarray, fps: float) -> SkeletonMotion:
    """SMPL-X axis-angle poses (T, 165) and root translation (T, 3) metres -> canonical SkeletonMotion at ``fps``.

    SMPL-X joint frames are world-aligned and its rest pose is a T-pose, so no alignment is needed.
    """
    local = quat_from_axis_angle(poses.reshape(len(poses), len(SMPLX_JOINTS), 3))  # (T, 55, 4)
    source_global, _ = source_forward_kinematics(np.array(SMPLX_PARENTS), local)
    skeleton = SourceSkeleton(list(SMPLX_JOINTS), np.array(SMPLX_PARENTS), np.zeros((len(SMPLX_JOINTS), 3)),
                              np.zeros((len(SMPLX_JOINTS), 3)))
    mapped = MappedSkeleton.build(skeleton, SMPLX)
    rotations = canonical_local_rotations(mapped, source_global, quat_identity((CANONICAL.num_joints,)))
    root = trans * (CANONICAL.height() / SMPLX_NOMINAL_HEIGHT_M)  # horizontal path; height set by grounding
    return SkeletonMotion(rotations, _ground_root_height(rotations, root), fps)


CAMERA_TO_UPRIGHT = np.array([1.0, 0.0, 0.0, 0.0])  # 180 deg about X: OpenCV camera (y down, z away) to Y-up, +Z


def upright_from_camera(motion: SkeletonMotion) -> SkeletonMotion:
    """A motion whose root is in an OpenCV camera frame (SHOW fits), turned Y-up and facing the camera, grounded."""
    rotations = motion.rotations.copy()
    rotations[:, 0] = quat_mul(np.broadcast_to(CAMERA_TO_UPRIGHT, rotations[:, 0].shape), rotations[:, 0])
    root = motion.root_position * np.array([1.0, -1.0, -1.0])  # (T, 3)
    return SkeletonMotion(rotations, _ground_root_height(rotations, root), motion.fps, motion.skeleton)


def _read_smplx_npz(path: Path) -> SkeletonMotion:
    try:
        with np.load(path, allow_pickle=False) as archive:
            missing = [key for key in ("poses", "trans") if key not in archive.files]
            if missing:
                raise UserError(f"{path}: not an SMPL-X motion file (missing {', '.join(missing)} arrays)")
            for key in ("poses", "trans"):
                check_file_size(archive.zip.getinfo(f"{key}.npy").file_size, f"{path}: {key}")
            poses = np.asarray(archive["poses"], dtype=np.float64)
            trans = np.asarray(archive["trans"], dtype=np.float64)
            fps = _npz_frame_rate(archive, path)
    except (OSError, ValueError, KeyError) as error:
        raise UserError(f"cannot read {path} as an SMPL-X .npz file: {error}") from None
    if poses.ndim != 2 or poses.shape[1] != SMPLX_AXIS_ANGLE_DIM or trans.shape != (len(poses), 3):
        raise UserError(f"{path}: expected SMPL-X poses (T, {SMPLX_AXIS_ANGLE_DIM}) and trans (T, 3), "
                        f"got {poses.shape} and {trans.shape}")
    if len(poses) == 0:
        raise UserError(f"{path}: SMPL-X file has zero frames")
    if not (np.isfinite(poses).all() and np.isfinite(trans).all()):
        raise UserError(f"{path}: SMPL-X poses or trans hold NaN or infinite values")
    if np.abs(poses).max() > MAX_POSE_RADIANS:
        raise UserError(f"{path}: an SMPL-X pose value of {np.abs(poses).max():g} rad is beyond the supported "
                        f"±{MAX_POSE_RADIANS:g} (no joint turns that far)")
    check_clip_header(fps, len(poses), str(path))
    return retarget_smplx(poses, trans, fps)


def _npz_frame_rate(archive: np.lib.npyio.NpzFile, path: Path) -> float:
    """``mocap_frame_rate`` (one positive finite number), or 30 fps when the file has none."""
    if "mocap_frame_rate" not in archive.files:
        return MOTION_FPS
    value = np.asarray(archive["mocap_frame_rate"])
    if value.size != 1 or not np.issubdtype(value.dtype, np.number):
        raise UserError(f"{path}: mocap_frame_rate must be one number, got an array of shape {value.shape}")
    fps = float(value.reshape(()))
    if not (math.isfinite(fps) and fps > 0):
        raise UserError(f"{path}: mocap_frame_rate must be a positive finite number, got {fps:g}")
    return fps


def load_motion_file(path: str | Path, joint_map: Path | None = None, keep_hands: bool = False) -> SkeletonMotion:
    """Read a ``.bvh`` (any supported skeleton) or SMPL-X ``.npz`` as canonical SkeletonMotion at 30 fps.

    joint_map: a user JSON map file for BVH skeletons that are not detected automatically.
    keep_hands: a BVH that gesturecast wrote (the joints of ``CANONICAL_WITH_HANDS``) is read as it is, fingers
    included, instead of being retargeted to the 22 body joints (for drawing; the model sees body joints only).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".bvh":
        data = read_bvh(path)
        own = keep_hands and sorted(data.names) == sorted(CANONICAL_WITH_HANDS.names)
        user_map = load_joint_map(joint_map) if joint_map is not None else None
        motion = _motion_with_hands(data) if own else retarget_bvh(data, user_map, str(path)).motion
    elif suffix == ".npz":
        motion = _read_smplx_npz(path)
    else:
        raise UserError(f"{path}: unsupported motion file type '{path.suffix}' (expected .bvh or SMPL-X .npz)")
    check_root_path(motion.root_position, str(path))
    check_rotations(motion.rotations, str(path))
    return resample_motion(motion, MOTION_FPS)


def _motion_with_hands(data: BvhData) -> SkeletonMotion:
    """SkeletonMotion on ``CANONICAL_WITH_HANDS`` of a BVH with exactly its joints (our own output: T-pose rest, cm)."""
    columns = [data.names.index(name) for name in CANONICAL_WITH_HANDS.names]  # file order → skeleton order
    root = data.local_translations()[:, columns[0]] / BVH_UNITS_PER_METRE  # (T, 3) metres
    return SkeletonMotion(data.local_rotations()[:, columns], root, data.fps, CANONICAL_WITH_HANDS)


def motion_to_bvh(motion: SkeletonMotion, path: str | Path) -> None:
    """Write ``motion`` as a canonical-skeleton BVH in centimetres (Blender: import with Scale 0.01)."""
    write_bvh(canonical_bvh_data(motion.rotations, motion.root_position, motion.fps, motion.skeleton), path)
