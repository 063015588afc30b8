"""Retargeting onto the canonical skeleton: detection, solved T-pose, positions, SMPL-X, export."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import BvhData, read_bvh, write_bvh
from gesturecast.models.motion.joint_maps import SMPLX_PARENTS, load_joint_map
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.resample import resample_motion
from gesturecast.models.motion.retarget import load_motion_file, motion_to_bvh, retarget_bvh, source_forward_kinematics
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_rotate, quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL

DATA = Path(__file__).resolve().parents[3].parent / "shared" / "data"
RAW_CACHE = Path(__file__).resolve().parents[3] / ".cache" / "raw"  # where `gesturecast data build` unpacks
TEST_FRAMES = 300
MAX_OWN_PROPORTION_ERROR_M = 0.01
rng = np.random.default_rng(0)


def _first_frames(data: BvhData, count: int = TEST_FRAMES) -> BvhData:
    data.motion = data.motion[:count]
    return data


def _source_positions(data: BvhData, names: list[str]) -> np.ndarray:
    _, positions = source_forward_kinematics(data.parents, data.local_rotations(), data.local_translations())
    stripped = [n.split(":")[-1] for n in data.names]
    return positions[:, [stripped.index(n) for n in names]]  # (T, K, 3)


def _position_error(data: BvhData) -> tuple[float, float]:
    """Max error (m) on the source-proportioned canonical skeleton and on CANONICAL, over mapped joints."""
    result = retarget_bvh(data)
    mapped = [c for c, name in enumerate(CANONICAL.names) if result.joint_map.chain(name)]
    source = _source_positions(data, [result.joint_map.chain(CANONICAL.names[c])[0] for c in mapped]) * result.scale
    _, own = result.source_skeleton.forward_kinematics(result.motion.rotations, result.motion.root_position)
    _, canonical = CANONICAL.forward_kinematics(result.motion.rotations, result.motion.root_position)
    own_error = np.linalg.norm(own[:, mapped] - source, axis=-1).max()
    canonical_error = np.linalg.norm(canonical[:, mapped] - source, axis=-1).max()
    return float(own_error), float(canonical_error)


# ----------------------------------------------------------------------------- synthetic skeletons

def _hierarchy_bvh(joints: list[tuple[str, str | None, tuple[float, float, float]]], num_frames: int,
                   channel_order: str = "ZXY", twist: bool = False) -> BvhData:
    names = [j[0] for j in joints]
    parents = np.array([-1 if p is None else names.index(p) for _, p, _ in joints])
    rot_channels = tuple(f"{a}rotation" for a in channel_order)
    channels = [("Xposition", "Yposition", "Zposition", *rot_channels)] + [rot_channels] * (len(joints) - 1)
    angles = rng.uniform(-40, 40, size=(num_frames, len(joints), 3))
    root = np.array(joints[0][2]) + rng.normal(0, 3, size=(num_frames, 3))
    motion = np.concatenate([root, angles.reshape(num_frames, -1)], axis=1)
    offsets = np.array([j[2] for j in joints], float)
    end_sites = {j: 5.0 * offsets[j] / np.linalg.norm(offsets[j]) for j in range(len(joints)) if j not in parents}
    return BvhData(names, parents, offsets, channels, 1 / 60, motion, end_sites)


def _mixamo_joints(prefix: str = "mixamorig:") -> list[tuple[str, str | None, tuple[float, float, float]]]:
    table = [("Hips", None, (0, 100, 0)), ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 12, 0)),
             ("Spine2", "Spine1", (0, 14, 0)), ("Neck", "Spine2", (0, 15, 0)), ("Head", "Neck", (0, 10, 0))]
    for side, sign in (("Left", 1), ("Right", -1)):
        table += [(f"{side}Shoulder", "Spine2", (sign * 6, 10, 0)),
                  (f"{side}Arm", f"{side}Shoulder", (sign * 12, 0, 0)),
                  (f"{side}ForeArm", f"{side}Arm", (sign * 27, 0, 0)),
                  (f"{side}Hand", f"{side}ForeArm", (sign * 25, 0, 0)),
                  (f"{side}UpLeg", "Hips", (sign * 9, -5, 0)), (f"{side}Leg", f"{side}UpLeg", (0, -42, 0)),
                  (f"{side}Foot", f"{side}Leg", (0, -41, 0)), (f"{side}ToeBase", f"{side}Foot", (0, -5, 12))]
    return [(prefix + n, None if p is None else prefix + p, o) for n, p, o in table]


def _cmu_joints() -> list[tuple[str, str | None, tuple[float, float, float]]]:
    table = [("Hips", None, (0, 17, 0)), ("LowerBack", "Hips", (0, 0, 0)), ("Spine", "LowerBack", (0, 2.1, 0)),
             ("Spine1", "Spine", (0, 2.1, 0)), ("Neck", "Spine1", (0, 0, 0)), ("Neck1", "Neck", (0, 1.6, 0)),
             ("Head", "Neck1", (0, 1.7, 0))]
    for side, s in (("Left", 1), ("Right", -1)):
        short = side[0]
        table += [(f"{short}HipJoint", "Hips", (0, 0, 0)), (f"{side}UpLeg", f"{short}HipJoint", (s * 1.4, -1.8, 0.8)),
                  (f"{side}Leg", f"{side}UpLeg", (0, -7.0, 0)), (f"{side}Foot", f"{side}Leg", (0, -7.2, 0)),
                  (f"{side}ToeBase", f"{side}Foot", (0, -0.5, 2.2)), (f"{side}Shoulder", "Spine1", (0, 0, 0)),
                  (f"{side}Arm", f"{side}Shoulder", (s * 3.4, 1.2, 0)),
                  (f"{side}ForeArm", f"{side}Arm", (s * 5.2, 0, 0)),
                  (f"{side}Hand", f"{side}ForeArm", (s * 3.8, 0, 0))]
    order = {n: i for i, n in enumerate(["Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
                                         "RHipJoint", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"])}
    return sorted(table, key=lambda j: order.get(j[0], len(order)))


# Mixamo maps one joint per canonical joint: exact. CMU merges Neck + Neck1, whose chord shortens
# when Neck1 bends (random bends of up to 40 degrees here).
@pytest.mark.parametrize(("joints", "expected", "tolerance_m"), [(_mixamo_joints(), "Mixamo", 1e-9),
                                                                 (_mixamo_joints(""), "Mixamo", 1e-9),
                                                                 (_cmu_joints(), "CMU", 0.03)])
def test_detects_layout_and_reproduces_positions(joints: list, expected: str, tolerance_m: float,
                                                 tmp_path: Path) -> None:
    data = _hierarchy_bvh(joints, 40)
    result = retarget_bvh(data)
    assert result.joint_map.name == expected
    unmapped = [j for j, name in enumerate(data.names) if name.split(":")[-1] not in result.joint_map.source_joints()]
    for column in np.concatenate([data.channel_columns()[j] for j in unmapped] or [[]]).astype(int):
        data.motion[:, column] = 0.0  # like CMU's LHipJoint/RHipJoint, unmapped joints do not move
    own_error, _ = _position_error(data)
    assert own_error < tolerance_m
    path = tmp_path / "synthetic.bvh"
    write_bvh(data, path)
    motion = load_motion_file(path)
    assert motion.fps == 30.0 and motion.num_frames == 20  # 40 frames at 60 fps span 0.65 s


def test_identity_rest_maps_to_identity() -> None:
    data = _hierarchy_bvh(_mixamo_joints(), 3)
    data.motion[:, 3:] = 0.0
    rotations = retarget_bvh(data).motion.rotations
    np.testing.assert_allclose(np.abs(rotations[..., 3]), 1.0, atol=1e-9)


def test_user_map_file(tmp_path: Path) -> None:
    renamed = [("bone_" + n.replace("mixamorig:", ""), None if p is None else "bone_" + p.replace("mixamorig:", ""), o)
               for n, p, o in _mixamo_joints()]
    data = _hierarchy_bvh(renamed, 30)
    path = tmp_path / "custom.bvh"
    write_bvh(data, path)
    with pytest.raises(UserError, match="unknown skeleton layout"):
        load_motion_file(path)
    mixamo_chains = retarget_bvh(_hierarchy_bvh(_mixamo_joints(), 2)).joint_map.chains
    user_map = {name: ["bone_" + s for s in chain] for name, chain in mixamo_chains.items()}
    map_path = tmp_path / "map.json"
    map_path.write_text(json.dumps(user_map))
    motion = load_motion_file(path, map_path)
    assert motion.rotations.shape == (15, CANONICAL.num_joints, 4)
    map_path.write_text(json.dumps({**user_map, "LeftWing": ["x"]}))
    with pytest.raises(UserError, match="unknown canonical joints LeftWing"):
        load_motion_file(path, map_path)


def test_a_joint_map_larger_than_1_mib_is_refused_without_reading_it_all(tmp_path: Path) -> None:
    path = tmp_path / "map.json"
    path.write_text("{" + " " * (1 << 20) + "}")
    with pytest.raises(UserError, match="joint map .*map.json holds more than 1 MiB"):
        load_joint_map(path)


def test_missing_mapped_joints_are_named(tmp_path: Path) -> None:
    joints = [j for j in _mixamo_joints() if "LeftHand" not in j[0] and "RightToeBase" not in j[0]]
    path = tmp_path / "partial.bvh"
    write_bvh(_hierarchy_bvh(joints, 5), path)
    with pytest.raises(UserError, match="lacks joints LeftHand, RightToeBase") as info:
        load_motion_file(path)
    assert "\n" not in str(info.value)


def test_zero_offsets_name_the_leg_joints(tmp_path: Path) -> None:
    """All-zero OFFSETs leave nothing to scale the clip by: one line naming the legs, not a ZeroDivisionError."""
    path = tmp_path / "flat.bvh"
    data = _hierarchy_bvh([(n, p, (0, 0, 0)) for n, p, _ in _mixamo_joints()], 5)
    data.end_sites = {j: np.zeros(3) for j in data.end_sites}
    write_bvh(data, path)
    with pytest.raises(UserError, match=r"flat.bvh: the legs have no length .*zero OFFSET on LeftUpLeg, LeftLeg,"):
        load_motion_file(path)


def test_hips_path_beyond_a_kilometre_is_refused(tmp_path: Path) -> None:
    """Tiny legs scale a 90-unit root path to thousands of kilometres; an SMPL-X trans of 1e30 m likewise."""
    tiny = _hierarchy_bvh([(n, p, tuple(1e-6 * np.array(o))) for n, p, o in _mixamo_joints()], 5)
    write_bvh(tiny, tmp_path / "tiny.bvh")
    with pytest.raises(UserError, match="the Hips reach .* beyond the supported 1000 m"):
        load_motion_file(tmp_path / "tiny.bvh")
    np.savez(tmp_path / "far.npz", poses=np.zeros((4, 3 * len(SMPLX_PARENTS))), trans=np.full((4, 3), 1e30))
    with pytest.raises(UserError, match="far.npz: the Hips reach"):
        load_motion_file(tmp_path / "far.npz")


def test_unsupported_file_type(tmp_path: Path) -> None:
    path = tmp_path / "notes.txt"
    path.write_text("hello")
    with pytest.raises(UserError, match="unsupported motion file type"):
        load_motion_file(path)
    bvh = tmp_path / "notes.bvh"
    bvh.write_text("hello")
    with pytest.raises(UserError, match="not a BVH file"):
        load_motion_file(bvh)


# ----------------------------------------------------------------------------- real data

@pytest.mark.skipif(not (DATA / "zeggs").is_dir(), reason="shared data not available")
def test_zeggs_take() -> None:
    data = _first_frames(read_bvh(DATA / "zeggs" / "067_Speech_2_x_1_0.bvh"))
    result = retarget_bvh(data)
    assert result.joint_map.name == "ZeroEGGS"
    assert result.scale == pytest.approx(0.01, rel=1e-3)  # cm, same proportions as the canonical skeleton
    own_error, canonical_error = _position_error(data)
    assert own_error < MAX_OWN_PROPORTION_ERROR_M
    assert canonical_error < 0.03  # canonical offsets are this take's, left/right averaged


@pytest.fixture(scope="module")
def bandai(shared_data) -> Path:
    """Bandai Namco dataset 1, unpacked once from the shared archive into the ignored cache (~2 s)."""
    from gesturecast.models.dataset.sources import unpack_archive

    return unpack_archive(shared_data / "bandai" / "dataset-1.tar.xz", RAW_CACHE / "bandai")


@pytest.mark.parametrize("index", range(3))
def test_bandai_takes(bandai: Path, index: int) -> None:
    data = _first_frames(read_bvh(sorted(bandai.glob("*/data/dataset-1_*_normal_001.bvh"))[index]))
    result = retarget_bvh(data)
    assert result.joint_map.name == "Bandai Namco"
    own_error, _ = _position_error(data)
    assert own_error < MAX_OWN_PROPORTION_ERROR_M
    # solved T-pose frames: the head's local up/forward stay up/forward (not twisted), feet point forward
    rotations = result.motion.rotations
    global_rot, _ = CANONICAL.forward_kinematics(rotations, result.motion.root_position)
    head_up = quat_rotate(global_rot[:, CANONICAL.index("Head")], np.array([0.0, 1.0, 0.0]))
    assert np.median(head_up[:, 1]) > 0.8
    hips_forward = quat_rotate(global_rot[:, 0], np.array([0.0, 0.0, 1.0]))
    for foot in ("LeftFoot", "RightFoot"):
        foot_forward = quat_rotate(global_rot[:, CANONICAL.index(foot)], np.array([0.0, 0.0, 1.0]))
        assert np.median(np.sum(foot_forward * hips_forward, axis=-1)) > 0.5
    # elbows and knees are hinges: their canonical local rotations carry little twist about the bone
    for joint, bone_axis in (("LeftLowerArm", 0), ("RightLowerArm", 0), ("LeftLowerLeg", 1), ("RightLowerLeg", 1)):
        local = rotations[:, CANONICAL.index(joint)]  # (T, 4)
        twist = np.abs(local[:, bone_axis])  # sin(twist / 2) for a pure twist about the bone axis
        assert np.degrees(2 * np.arcsin(np.median(twist))) < 30


SMPLX_TO_CANONICAL = {"left_shoulder": "LeftUpperArm", "left_elbow": "LeftLowerArm", "right_knee": "RightLowerLeg",
                      "spine3": "UpperChest", "head": "Head", "left_ankle": "LeftFoot"}
SMPLX_INDEX = {"left_shoulder": 16, "left_elbow": 18, "right_knee": 5, "spine3": 9, "head": 15, "left_ankle": 7}


@pytest.mark.skipif(not (DATA / "beat2").is_dir(), reason="shared data not available")
def test_smplx_bone_directions() -> None:
    archive = np.load(DATA / "beat2" / "2_scott_0_1_1.npz")
    poses = archive["poses"][:TEST_FRAMES].astype(np.float64)
    motion = load_motion_file(DATA / "beat2" / "2_scott_0_1_1.npz").slice(0, TEST_FRAMES)
    smplx_global, _ = source_forward_kinematics(np.array(SMPLX_PARENTS), quat_from_axis_angle(poses.reshape(-1, 55, 3)))
    canonical_global, _ = CANONICAL.forward_kinematics(motion.rotations, motion.root_position)
    for smplx_name, canonical_name in SMPLX_TO_CANONICAL.items():
        j = CANONICAL.index(canonical_name)
        bone = CANONICAL.offsets[j + 1] if canonical_name != "Head" else np.array([0.0, 1.0, 0.0])
        expected = quat_rotate(smplx_global[:, SMPLX_INDEX[smplx_name]], np.broadcast_to(bone, (TEST_FRAMES, 3)))
        actual = quat_rotate(canonical_global[:, j], np.broadcast_to(bone, (TEST_FRAMES, 3)))
        np.testing.assert_allclose(actual, expected, atol=1e-9)
    _, positions = CANONICAL.forward_kinematics(motion.rotations, motion.root_position)
    assert abs(np.percentile(positions[..., 1].min(axis=1), 50)) < 0.15  # feet on the floor


def test_resample_slerps_and_keeps_span() -> None:
    angles = np.linspace(0, 1.0, 61)[:, None, None] * np.array([0.0, 1.0, 0.0])  # (61, 1, 3) 1 rad over 1 s
    rotations = np.repeat(quat_from_axis_angle(angles), CANONICAL.num_joints, axis=1)
    root = np.linspace(0, 2.0, 61)[:, None] * np.array([1.0, 0.0, 0.0])
    out = resample_motion(SkeletonMotion(rotations, root, fps=60.0), 30.0)
    assert out.num_frames == 31 and out.fps == 30.0
    np.testing.assert_allclose(quat_to_axis_angle(out.rotations[:, 0])[:, 1], np.linspace(0, 1.0, 31), atol=1e-9)
    np.testing.assert_allclose(out.root_position[:, 0], np.linspace(0, 2.0, 31), atol=1e-12)
    slow = resample_motion(SkeletonMotion(rotations[:25], root[:25], fps=24.0), 30.0)
    assert slow.num_frames == 31  # 1 s at 24 fps -> 1 s at 30 fps
    np.testing.assert_allclose(quat_to_axis_angle(slow.rotations[:, 0])[:, 1], np.linspace(0, 24 / 60, 31), atol=1e-9)


def test_motion_to_bvh_round_trip(tmp_path: Path) -> None:
    rotations = quat_from_axis_angle(rng.normal(0, 0.5, size=(10, CANONICAL.num_joints, 3)))
    root = rng.normal(0, 1, size=(10, 3))
    path = tmp_path / "canonical.bvh"
    motion_to_bvh(SkeletonMotion(rotations, root), path)
    data = read_bvh(path)
    assert data.names == list(CANONICAL.names)
    np.testing.assert_allclose(data.offsets, CANONICAL.offsets * 100)  # centimetres
    back = retarget_bvh(data).motion
    dots = np.abs(np.sum(back.rotations * rotations, axis=-1))
    assert np.degrees(2 * np.arccos(np.clip(dots, -1, 1))).max() < 1e-4
    np.testing.assert_allclose(back.root_position, root, atol=1e-6)


def test_bandai_tpose_is_the_same_for_every_take(bandai: Path) -> None:
    """The solved rest alignment depends on the rig, not on the motion (waving takes included)."""
    from gesturecast.models.motion.rest_alignment import MappedSkeleton, SourceSkeleton, joint_tips, solve_tpose

    solved = []
    for name in ("bye_normal_001", "byebye_active_001", "walk_musical_001"):
        data = _first_frames(read_bvh(next(bandai.glob(f"*/data/dataset-1_{name}.bvh"))))
        source = SourceSkeleton(data.names, data.parents, data.offsets,
                                joint_tips(data.parents, data.offsets, data.end_sites))
        global_rot, _ = source_forward_kinematics(data.parents, data.local_rotations())
        solved.append(solve_tpose(MappedSkeleton.build(source, retarget_bvh(data).joint_map), global_rot))
    for other in solved[1:]:
        angle = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(other * solved[0], axis=-1)), 0, 1)))
        assert angle.max() < 1.0


def test_a_motion_prompt_with_huge_finite_rotations_loads_finite(tmp_path):
    """Every 7th channel at 1e308 (a valid BVH) gave NaN rotations, so NaN poses from ``--motion-prompt``."""
    motion = SkeletonMotion(quat_from_axis_angle(np.full((4, CANONICAL.num_joints, 3), 0.3)), np.zeros((4, 3)) + 1.0)
    motion_to_bvh(motion, tmp_path / "plain.bvh")
    data = read_bvh(tmp_path / "plain.bvh")
    data.motion[:, 3::7] = 1e308  # rotation channels only: positions stay within their bound
    write_bvh(data, tmp_path / "huge.bvh")
    assert np.isfinite(load_motion_file(tmp_path / "huge.bvh").rotations).all()
