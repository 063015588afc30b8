"""`generate -o FILE` picks its writer by the file name: .vrma → VRM Animation, anything else → BVH."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.bridges.gltf_binary import read_glb
from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.run.offline_generate import BvhFrameWriter, motion_writer

FRAMES = 5


def t_pose(seq: int) -> PoseFrame:
    rotations = np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1))  # (J, 4)
    return PoseFrame(seq, seq / 30.0, seq / 30.0, CANONICAL_WITH_HANDS.offsets[0].copy(), rotations)


@pytest.mark.parametrize("name", ["take.vrma", "TAKE.VRMA", "take.bvh"])
def test_the_suffix_chooses_the_format(tmp_path, name):
    path = tmp_path / name
    with motion_writer(path) as writer:
        writer.write([t_pose(i) for i in range(FRAMES)])
        writer.save()
    if name.lower().endswith(".vrma"):
        document, _ = read_glb(path.read_bytes())
        assert document["accessors"][0]["count"] == FRAMES
    else:
        assert isinstance(writer, BvhFrameWriter) and read_bvh(path).motion.shape[0] == FRAMES


@pytest.mark.parametrize("name", ["take", "take.glb", "take.txt"])
def test_an_unknown_suffix_is_refused_before_anything_is_written(tmp_path, name):
    with pytest.raises(UserError, match=r"name a \.bvh or \.vrma file"):
        motion_writer(tmp_path / name)
    assert list(tmp_path.iterdir()) == []
