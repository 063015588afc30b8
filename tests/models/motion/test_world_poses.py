"""Arms from the 9-joint world-pose format (``zeggs_upper``): solver accuracy, real data, bad files."""

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.dataset.sources import zeggs_upper_takes
from gesturecast.models.motion.body_parts import ARM_JOINTS
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.retarget import retarget_bvh
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_rotate
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.motion.world_poses import (
    angle_errors_deg,
    kabsch,
    load_world_pose_motion,
    measure_world_pose_fit,
    read_world_poses,
)

TAKE = "001_Neutral_0_x_1_0"


@pytest.fixture(scope="module")
def reference_bvh(shared_data):
    return shared_data / "zeggs" / "067_Speech_2_x_1_0.bvh"


def test_kabsch_recovers_a_rotation_from_two_directions():
    rotation = quat_from_axis_angle(np.array([0.3, -1.1, 0.7]))  # (4,)
    source = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])  # (2, 3)
    target = quat_rotate(np.broadcast_to(rotation, (2, 4)), source)
    assert angle_errors_deg(kabsch(source, target), rotation) < 1e-6


def test_solver_recovers_the_reference_takes_own_arms(reference_bvh):
    """Half of the full-body take is the reference; the other half, given random rest frames, is solved back."""
    retargeted = retarget_bvh(read_bvh(reference_bvh))
    errors = measure_world_pose_fit(retargeted.motion, retargeted.source_skeleton)
    assert set(errors) == set(ARM_JOINTS)
    for side in ("Left", "Right"):
        assert errors[f"{side}Shoulder"] < 2.0 and errors[f"{side}UpperArm"] < 2.0  # bones: exact but clavicle twist
        assert errors[f"{side}LowerArm"] < 5.0
        assert errors[f"{side}Hand"] < 20.0  # from mean wrist directions only (no finger positions)


def test_real_world_pose_take_keeps_the_observed_elbow_angles(shared_data, reference_bvh):
    path = shared_data / "zeggs_upper" / f"{TAKE}.npy"
    motion = load_world_pose_motion(path, reference_bvh)
    poses = read_world_poses(path)
    assert motion.fps == 30 and abs(motion.num_frames - len(poses.positions) / 2) <= 1
    others = [i for i, name in enumerate(CANONICAL.names) if name not in ARM_JOINTS]
    assert np.allclose(motion.rotations[:, others], [0.0, 0.0, 0.0, 1.0])  # masked parts: never invented
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        upper = poses.position(f"{side}LowerArm") - poses.position(f"{side}UpperArm")  # (T, 3)
        lower = poses.position(f"{side}Hand") - poses.position(f"{side}LowerArm")
        cosine = np.sum(upper * lower, -1) / np.linalg.norm(upper, axis=-1) / np.linalg.norm(lower, axis=-1)
        observed = np.degrees(np.arccos(np.clip(cosine, -1, 1)))[::2][: motion.num_frames]  # 60 → 30 fps
        bone = np.broadcast_to([sign, 0.0, 0.0], (motion.num_frames, 3))
        bent = quat_rotate(motion.rotations[:, CANONICAL.index(f"{side}LowerArm")], bone)
        solved = np.degrees(np.arccos(np.clip(np.sum(bent * bone, -1), -1, 1)))
        assert np.median(np.abs(solved - observed)) < 1.0


def test_shared_world_pose_folder_is_two_arms_only_neutral_takes(shared_data, reference_bvh):
    takes = zeggs_upper_takes(shared_data / "zeggs_upper", reference_bvh)
    assert [t.name for t in takes] == ["001_Neutral_0_x_1_0", "003_Neutral_2_x_1_0"]
    assert all(t.parts == ("arms",) and t.style == "neutral" and t.audio_path and not t.held_out for t in takes)


@pytest.mark.parametrize(("array", "message"), [
    (np.zeros((10, 8, 7), np.float32), "expected world poses of shape"),
    (np.full((10, 9, 7), np.nan, np.float32), "NaN or infinite"),
    (np.ones((10, 9, 7), np.float32), "not unit quaternions"),
])
def test_bad_world_pose_files_are_one_line_user_errors(tmp_path, array, message):
    path = tmp_path / "take.npy"
    np.save(path, array)
    with pytest.raises(UserError, match=message):
        read_world_poses(path)


def test_unreadable_world_pose_file_is_a_user_error(tmp_path):
    path = tmp_path / "take.npy"
    path.write_bytes(b"not numpy")
    with pytest.raises(UserError, match="cannot read"):
        read_world_poses(path)


def test_missing_reference_is_a_user_error(shared_data, tmp_path):
    with pytest.raises(UserError, match="full-body ZeroEGGS BVH"):
        zeggs_upper_takes(shared_data / "zeggs_upper", tmp_path / "none.bvh")
