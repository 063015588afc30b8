"""A gesture's imposed chains keep their body-frame rotation under generated (or another clip's) parents."""

import numpy as np

from gesturecast.models.motion.body_parts import joint_columns
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.models.motion.rotations import matrix_from_6d, quat_from_axis_angle, quat_to_6d, quat_to_matrix
from gesturecast.realtime.gestures.clips import rotation_columns
from gesturecast.realtime.gestures.cues import GestureClip, part_clip
from gesturecast.realtime.gestures.reattach import (
    CHAIN,
    body_frame_roots,
    parent_rotation,
    placed_roots,
    reattach,
)

RAISED = quat_from_axis_angle(np.array([0.0, 0.0, 1.2]))  # a recorded arm raised
LEAN = quat_from_axis_angle(np.array([0.4, 0.0, 0.0]))  # a generated joint leaning forward


def features_with(rotations: dict[str, np.ndarray], frames: int = 4) -> np.ndarray:
    """(frames, D) features: identity rotations (and the hips' at columns 4..9) except those named."""
    features = np.zeros((frames, FEATURE_DIM), np.float32)
    identity = quat_to_6d(np.array([0.0, 0.0, 0.0, 1.0]))
    features[:, 4:] = np.tile(identity, (FEATURE_DIM - 4) // 6)
    for joint, quat in rotations.items():
        cols = list(range(4, 10)) if joint == "Hips" else joint_columns(joint)
        features[:, cols] = quat_to_6d(quat)
    return features


def body_frame(features: np.ndarray, joint: str, above: tuple[str, ...]) -> np.ndarray:
    """(n, 3, 3) ``joint``'s rotation in the body frame."""
    return parent_rotation(features, above) @ matrix_from_6d(features[:, joint_columns(joint)].astype(float))


def same_rotation(matrices: np.ndarray, quat: np.ndarray) -> bool:
    return bool(np.allclose(matrices, quat_to_matrix(quat), atol=1e-5))


def imposed(columns: np.ndarray, frames: int = 4) -> np.ndarray:
    """(frames, D) pose weights of 1 on ``columns``."""
    return np.tile(columns.astype(np.float32), (frames, 1))


def placed(clip: np.ndarray, columns: np.ndarray, share: float = 1.0) -> list:
    """The roots of ``clip`` imposing ``columns``, over all its frames, with ``share`` of the pose target."""
    frames = clip.shape[0]
    return placed_roots(body_frame_roots(clip, columns), clip, slice(0, frames), np.full((frames, 1), share),
                        np.ones_like(clip))


def test_a_leaning_generated_chest_does_not_turn_the_recorded_shoulders():
    clip = features_with({"LeftShoulder": RAISED, "RightShoulder": RAISED})
    arms = rotation_columns(("arms",), FEATURE_DIM)
    roots = body_frame_roots(clip, arms)
    assert [above for _, above, _ in roots] == [CHAIN, CHAIN]
    blended = reattach(features_with({"Chest": LEAN}), clip, imposed(arms), placed(clip, arms))
    assert same_rotation(body_frame(blended, "LeftShoulder", CHAIN), RAISED)
    assert body_frame_roots(clip, rotation_columns(("arms", "torso", "legs"), FEATURE_DIM)) == []  # a bow's hips


def test_an_arms_and_torso_clip_keeps_its_spine_upright_on_generated_hips():
    clip = features_with({"Spine": RAISED})
    moved = rotation_columns(("arms", "torso"), FEATURE_DIM)
    roots = body_frame_roots(clip, moved)
    assert [above for _, above, _ in roots] == [()]  # the spine; the shoulders hang from the clip's own chest
    blended = reattach(features_with({"Hips": LEAN}), clip, imposed(moved), placed(clip, moved))
    assert same_rotation(body_frame(blended, "Spine", ()), RAISED)
    assert same_rotation(body_frame(blended, "LeftShoulder", CHAIN), RAISED)  # the whole upper body as recorded


def test_shoulders_follow_another_clips_imposed_chest_not_the_generated_one():
    wave = features_with({"LeftShoulder": RAISED, "RightShoulder": RAISED})
    bow = features_with({"Chest": LEAN})  # a bow's torso playing alongside
    arms, torso = rotation_columns(("arms",), FEATURE_DIM), rotation_columns(("torso",), FEATURE_DIM)
    target = np.where(arms, wave, bow)
    generated = features_with({"Chest": quat_from_axis_angle(np.array([-0.3, 0.0, 0.0]))})
    blended = reattach(generated, target, imposed(arms | torso), placed(wave, arms))
    assert same_rotation(body_frame(blended, "LeftShoulder", CHAIN), RAISED)


def test_a_guide_without_its_torso_reattaches_its_shoulders():
    features = features_with({"Spine": LEAN, "LeftShoulder": RAISED, "RightShoulder": RAISED}, 8)
    moved = rotation_columns(("arms", "torso"), FEATURE_DIM)
    guide = GestureClip("guide", np.zeros((2, 4), np.float32), np.ones(4, bool), 0, features, moved,
                        tuple(body_frame_roots(features, moved)))
    arms_only = part_clip(guide, np.ones(4, bool), rotation_columns(("arms",), FEATURE_DIM))
    assert [above for _, above, _ in arms_only.roots] == [CHAIN, CHAIN]


def test_a_clip_fading_out_hands_its_shoulders_over_in_proportion():
    wave = features_with({"LeftShoulder": RAISED, "RightShoulder": RAISED})
    arms = rotation_columns(("arms",), FEATURE_DIM)
    generated = features_with({"Chest": LEAN})
    gone = reattach(generated, wave, imposed(arms), placed(wave, arms, share=0.0))
    assert np.allclose(gone, np.where(arms, wave, generated), atol=1e-6)  # no share: its local rotations
    half = reattach(generated, wave, imposed(arms), placed(wave, arms, share=0.5))
    full = reattach(generated, wave, imposed(arms), placed(wave, arms))
    cols = joint_columns("LeftShoulder")
    assert np.allclose(half[:, cols], (gone[:, cols] + full[:, cols]) / 2, atol=1e-6)
