"""Streaming BVH recorder: valid after every frame, same numbers as motion_to_bvh."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.bridges.bvh_recorder import BvhRecorder
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.retarget import motion_to_bvh
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

NUM_FRAMES = 12


def _poses() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    rotations = quat_from_axis_angle(rng.normal(0, 0.4, size=(NUM_FRAMES, CANONICAL_WITH_HANDS.num_joints, 3)))
    return rotations, rng.normal(0, 1, size=(NUM_FRAMES, 3))


def test_recording_matches_offline_export(tmp_path: Path) -> None:
    rotations, root = _poses()
    with BvhRecorder(tmp_path / "live.bvh") as recorder:
        for k in range(NUM_FRAMES):
            recorder.send(PoseFrame(k, k / 30, k / 30 + 0.2, root[k], rotations[k]))
    motion_to_bvh(SkeletonMotion(rotations, root, skeleton=CANONICAL_WITH_HANDS), tmp_path / "offline.bvh")
    live, offline = read_bvh(tmp_path / "live.bvh"), read_bvh(tmp_path / "offline.bvh")
    assert live.num_frames == NUM_FRAMES and live.fps == offline.fps
    np.testing.assert_array_equal(live.motion, offline.motion)
    assert live.names == offline.names
    np.testing.assert_array_equal(live.offsets, offline.offsets)


def test_interrupted_recording_is_readable_and_replaces_the_target_only_when_closed(tmp_path: Path) -> None:
    rotations, root = _poses()
    target = tmp_path / "crash.bvh"
    target.write_text("an older take\n")
    recorder = BvhRecorder(target)
    for k in range(5):
        recorder.send(PoseFrame(k, 0.0, 0.0, root[k], rotations[k]))
        assert read_bvh(recorder.partial_path).num_frames == k + 1  # never closed (a killed run): still valid
        assert target.read_text() == "an older take\n"
    recorder.close()
    assert read_bvh(target).num_frames == 5 and not recorder.partial_path.exists()


def test_a_recording_closed_without_frames_replaces_nothing(tmp_path: Path) -> None:
    kept, absent = tmp_path / "kept.bvh", tmp_path / "absent.bvh"
    kept.write_text("an older take\n")
    for target in (kept, absent):
        BvhRecorder(target).close()  # e.g. the input failed before its first frame
    assert kept.read_text() == "an older take\n" and sorted(tmp_path.iterdir()) == [kept]
