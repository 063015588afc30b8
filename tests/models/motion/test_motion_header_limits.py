"""Crafted motion headers are refused before anything is allocated (BVH frame time, NPZ frame rate, sizes)."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.motion import MAX_CLIP_SECONDS, MAX_FILE_FPS
from gesturecast.models.motion.retarget import load_motion_file

SMPLX_POSE_DIM = 165
TWO_JOINT_BVH = """HIERARCHY
ROOT Hips
{{
\tOFFSET 0 0 0
\tCHANNELS 3 Zrotation Xrotation Yrotation
\tEnd Site
\t{{
\t\tOFFSET 0 1 0
\t}}
}}
MOTION
Frames: {frames}
Frame Time: {frame_time}
{rows}"""


def bvh_text(frames: int, frame_time: float) -> str:
    return TWO_JOINT_BVH.format(frames=frames, frame_time=frame_time, rows="0 0 0\n" * frames)


@pytest.mark.parametrize("frame_time", [1000.0, 0.5 / MAX_FILE_FPS])
def test_a_bvh_frame_time_outside_the_limits_is_one_line_error(tmp_path, frame_time):
    """Before: `Frame Time: 1000` made the 30 fps resampler ask for 2.9 GiB."""
    path = tmp_path / "crafted.bvh"
    path.write_text(bvh_text(3, frame_time))
    with pytest.raises(UserError, match="outside the supported"):
        read_bvh(path)


def test_a_bvh_longer_than_the_limit_is_refused(tmp_path):
    path = tmp_path / "long.bvh"
    path.write_text(bvh_text(int(MAX_CLIP_SECONDS) + 1, 1.0))
    with pytest.raises(UserError, match="longer than the supported"):
        read_bvh(path)


def write_smplx(path, frames: int, fps: float) -> None:
    np.savez(path, poses=np.zeros((frames, SMPLX_POSE_DIM)), trans=np.zeros((frames, 3)),
             mocap_frame_rate=np.float64(fps))


def test_an_npz_frame_rate_outside_the_limits_is_one_line_error(tmp_path):
    """Before: an NPZ with 1e-4 fps asked for 11.6 GiB when resampled to 30 fps."""
    path = tmp_path / "crafted.npz"
    write_smplx(path, 4, 1e-4)
    with pytest.raises(UserError, match="frame rate 0.0001 fps is outside the supported"):
        load_motion_file(path)


def test_a_normal_npz_still_loads(tmp_path):
    path = tmp_path / "ok.npz"
    write_smplx(path, 4, 60.0)
    assert load_motion_file(path).num_frames == 2  # 3 intervals at 60 fps -> 0.05 s -> 2 frames at 30 fps
