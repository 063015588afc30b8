"""The pose JSON's closing fields: what the run adds after the frames (the gesture cues' outcomes)."""

import json

import numpy as np

from gesturecast.bridges.pose_json import PoseJsonWriter
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON


def test_the_closing_fields_follow_the_frames(tmp_path):
    cues = {"on time": 2, "late": 0, "blended": 1, "merged": 0, "dropped": 1, "notes": ["gesture bow (thanks) ..."]}
    frame = PoseFrame(0, 0.0, 0.5, SKELETON.offsets[0], np.tile([0.0, 0.0, 0.0, 1.0], (SKELETON.num_joints, 1)),
                      gesture="wave")
    with PoseJsonWriter(tmp_path / "take.json", closing=lambda: {"gesture_cues": cues}) as writer:
        writer.write([frame])
        writer.save()
    document = json.loads((tmp_path / "take.json").read_text())
    assert document["gesture_cues"] == cues and document["frames"][0]["gesture"] == "wave"
