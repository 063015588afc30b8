"""An arms-only gesture keeps its shoulders' rotation in the body frame under a generated torso."""

import numpy as np

from gesturecast.models.motion.body_parts import joint_columns
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.models.motion.rotations import quat_from_6d, quat_from_axis_angle, quat_mul, quat_to_6d
from gesturecast.realtime.gestures.arm_reattach import body_frame_shoulders, chain_rotation, reattach
from gesturecast.realtime.gestures.clips import rotation_columns


def features_with(rotations: dict[str, np.ndarray], frames: int = 4) -> np.ndarray:
    """(frames, D) features: identity rotations (and the hips' at columns 4..9) except those named."""
    features = np.zeros((frames, FEATURE_DIM), np.float32)
    identity = quat_to_6d(np.array([0.0, 0.0, 0.0, 1.0]))
    features[:, 4:] = np.tile(identity, (FEATURE_DIM - 4) // 6)
    for joint, quat in rotations.items():
        features[:, joint_columns(joint)] = quat_to_6d(quat)
    return features


def test_a_leaning_generated_chest_does_not_turn_the_recorded_shoulders():
    shoulder = quat_from_axis_angle(np.array([0.0, 0.0, 1.2]))  # the recorded arm raised
    clip = features_with({"LeftShoulder": shoulder, "RightShoulder": shoulder})
    arms = rotation_columns(("arms",), FEATURE_DIM)
    shoulders = body_frame_shoulders(clip, arms)
    assert len(shoulders) == 2
    generated = features_with({"Chest": quat_from_axis_angle(np.array([0.4, 0.0, 0.0]))})  # leaning forward
    target = reattach(np.where(arms, clip, 0.0), generated, shoulders)
    blended = np.where(arms, target, generated)  # the imposed columns at weight 1
    cols = joint_columns("LeftShoulder")
    body_frame = quat_mul(chain_rotation(blended), quat_from_6d(blended[:, cols].astype(np.float64)))
    assert np.allclose(np.abs(np.sum(body_frame * shoulder, axis=-1)), 1.0, atol=1e-5)  # the same rotation
    assert body_frame_shoulders(clip, rotation_columns(("arms", "torso"), FEATURE_DIM)) == []  # a bow's own torso
