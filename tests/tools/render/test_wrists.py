"""`gesturecast render --wrists`: body-frame wrist tracks, the side-by-side picture of a real take, errors."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from gesturecast.cli import main
from gesturecast.errors import USER_ERROR_EXIT_CODE
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.retarget import load_motion_file, motion_to_bvh
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_from_yaw, quat_mul
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.tools.render.wrists import body_frame_wrists

TAKE = Path("zeggs") / "067_Speech_2_x_1_0.bvh"


def test_walking_and_turning_do_not_move_the_body_frame_wrists():
    rng = np.random.default_rng(3)
    frames = 20
    pose = quat_from_axis_angle(rng.normal(scale=0.3, size=(frames, CANONICAL.num_joints, 3)))  # (T, J, 4)
    still = SkeletonMotion(pose, np.tile([0.0, 0.9, 0.0], (frames, 1)), 30.0, CANONICAL)
    turned_pose = pose.copy()
    turned_pose[:, 0] = quat_mul(quat_from_yaw(np.linspace(0.0, 3.0, frames)), pose[:, 0])
    walking = np.column_stack([np.linspace(0, 2, frames), np.full(frames, 0.9), np.linspace(0, -1, frames)])
    moved = SkeletonMotion(turned_pose, walking, 30.0, CANONICAL)
    np.testing.assert_allclose(body_frame_wrists(moved), body_frame_wrists(still), atol=1e-9)
    left_x = body_frame_wrists(SkeletonMotion(np.tile([0.0, 0.0, 0.0, 1.0], (1, CANONICAL.num_joints, 1)),
                                      np.array([[0.0, 0.9, 0.0]]), 30.0, CANONICAL))[0, 0, 0]
    assert left_x > 0.5  # T-pose: the left wrist is far out on +X


def test_a_real_take_beside_a_copy_of_itself(shared_data, tmp_path):
    copy = tmp_path / "copy.bvh"
    motion_to_bvh(load_motion_file(shared_data / TAKE).slice(0, 150), copy)
    out = tmp_path / "wrists.png"
    code = main(["render", "--wrists", str(shared_data / TAKE), str(copy), "-o", str(out), "--seconds", "4",
                 "--labels", "real,copy"])
    assert code == 0
    with Image.open(out) as image:
        assert image.size[0] > image.size[1] / 2  # two columns side by side
        pixels = np.asarray(image.convert("L"))
    assert (pixels < 128).mean() > 0.01  # something is drawn


@pytest.mark.parametrize(("flags", "message"), [
    (["--labels", "one"], "--labels has 1 names for 2 files"),
    (["--raw"], "--wrists draws retargeted motion (the canonical wrists): drop --raw"),
])
def test_bad_wrist_flags_are_one_line(shared_data, tmp_path, capsys, flags, message):
    take = str(shared_data / TAKE)
    assert main(["render", "--wrists", take, take, "-o", str(tmp_path / "w.png"), *flags]) == USER_ERROR_EXIT_CODE
    assert capsys.readouterr().err == f"gesturecast render: error: {message}\n"


def test_several_files_need_wrists(shared_data, tmp_path, capsys):
    take = str(shared_data / TAKE)
    assert main(["render", take, take, "-o", str(tmp_path / "w.png")]) == USER_ERROR_EXIT_CODE
    assert "several are drawn only with --wrists" in capsys.readouterr().err
