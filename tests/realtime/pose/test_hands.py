"""Procedural hands: a relaxed curl toward the palm on both hands, opening with arm activity, deterministic."""

import numpy as np
import pytest

from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_identity, quat_rotate
from gesturecast.models.motion.skeleton import (
    CANONICAL,
    CANONICAL_WITH_HANDS,
    FINGERS,
    FINGERTIPS,
    NUM_FINGER_JOINTS,
    SIDES,
    finger_joint_names,
)
from gesturecast.realtime.pose.hands import HandConfig, HandPose

FPS = 30.0
STILL = HandConfig(variation_deg=0.0)  # no per-finger wobble: isolates the curl and the openness
SIDE_SIGN = {"Left": 1.0, "Right": -1.0}  # the left arm points +X in the T-pose


def fingertips(pose: np.ndarray) -> dict[str, np.ndarray]:
    """World fingertip positions (3,) by distal joint name, of a (52, 4) pose with the root at rest."""
    global_rot, positions = CANONICAL_WITH_HANDS.forward_kinematics(pose)  # (52, 4), (52, 3)
    tips = {}
    for name, tip in FINGERTIPS.items():
        j = CANONICAL_WITH_HANDS.index(name)
        tips[name] = positions[j] + quat_rotate(global_rot[j], np.asarray(tip))
    return tips


def settle(hands: HandPose, body: np.ndarray, frames: int = 60) -> np.ndarray:
    """The pose after holding ``body`` still for ``frames`` frames (the openness has settled)."""
    for k in range(frames):
        pose = hands.append(body, k / FPS)
    return pose


def curl_depth(pose: np.ndarray, side: str) -> np.ndarray:
    """(5,) how far below the palm (−Y, metres) each fingertip of ``side`` is, from the T-pose body."""
    tips = fingertips(pose)
    flat = fingertips(np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1)))
    return np.array([flat[f"{side}{f}Distal"][1] - tips[f"{side}{f}Distal"][1] for f in FINGERS])


def curl_depth_of(pose: np.ndarray) -> np.ndarray:
    """(2, 5) flexion of each finger (sum of its three joint angles, radians)."""
    angles = 2 * np.arccos(np.clip(np.abs(pose[:, 3]), 0.0, 1.0))  # (52,)
    per_joint = np.array([angles[[CANONICAL_WITH_HANDS.index(n) for n in finger_joint_names(side)]] for side in SIDES])
    return per_joint.reshape(len(SIDES), len(FINGERS), -1).sum(axis=-1)  # (2, 5)


def test_output_keeps_the_body_and_appends_unit_finger_rotations():
    body = quat_from_axis_angle(np.random.default_rng(1).normal(0.0, 0.3, (CANONICAL.num_joints, 3)))
    pose = HandPose(FPS).append(body, 0.0)
    assert pose.shape == (CANONICAL.num_joints + NUM_FINGER_JOINTS, 4) == (52, 4)
    np.testing.assert_array_equal(pose[: CANONICAL.num_joints], body)
    np.testing.assert_allclose(np.linalg.norm(pose, axis=-1), 1.0, atol=1e-12)


@pytest.mark.parametrize("side", SIDES)
def test_relaxed_curl_moves_every_fingertip_toward_the_palm_more_from_index_to_little(side):
    """T-pose body (palms down): every fingertip, thumb included, goes down (−Y) and back toward the wrist."""
    pose = settle(HandPose(FPS, config=STILL), quat_identity((CANONICAL.num_joints,)))
    depth = curl_depth(pose, side)  # (5,) thumb, index, middle, ring, little
    assert (depth > 0.01).all(), depth
    tips = fingertips(pose)
    flat = fingertips(np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1)))
    for finger in FINGERS[1:]:
        name = f"{side}{finger}Distal"
        assert SIDE_SIGN[side] * (tips[name][0] - flat[name][0]) < 0  # pulled back toward the wrist
    flexion = curl_depth_of(pose)[SIDES.index(side), 1:]  # (4,) index, middle, ring, little
    assert np.all(np.diff(flexion) > 0)  # index < middle < ring < little


def test_both_hands_mirror_each_other():
    pose = settle(HandPose(FPS, config=STILL), quat_identity((CANONICAL.num_joints,)))
    np.testing.assert_allclose(curl_depth(pose, "Left"), curl_depth(pose, "Right"), atol=1e-9)
    left, right = (pose[[CANONICAL_WITH_HANDS.index(n) for n in finger_joint_names(s)]] for s in SIDES)
    np.testing.assert_allclose(right, left * np.array([1.0, -1.0, -1.0, 1.0]), atol=1e-9)  # mirror across X


def swinging_body(t: np.ndarray, amplitude_rad: float) -> np.ndarray:
    """(T, 22, 4) arms hanging (rotated down 70°) and swinging forward/back with ``amplitude_rad`` at 1.5 Hz."""
    axis_angles = np.zeros((len(t), CANONICAL.num_joints, 3))
    for side, sign in SIDE_SIGN.items():
        axis_angles[:, CANONICAL.index(f"{side}UpperArm"), 2] = -sign * np.radians(70.0)
        axis_angles[:, CANONICAL.index(f"{side}UpperArm"), 1] = amplitude_rad * np.sin(2 * np.pi * 1.5 * t)
    return quat_from_axis_angle(axis_angles)


def test_fast_wrists_open_the_hand_a_little():
    t = np.arange(90) / FPS
    openness = {}
    for amplitude in (0.0, 0.8):
        hands = HandPose(FPS, config=STILL)
        for k, body in enumerate(swinging_body(t, amplitude)):
            pose = hands.append(body, t[k])
        openness[amplitude] = (hands.openness.copy(), curl_depth_of(pose))
    still, moving = openness[0.0], openness[0.8]
    assert (moving[0] > still[0] + 0.1).all() and (moving[0] <= STILL.max_open).all()
    assert (moving[1] < still[1]).all()  # less curled: every fingertip closer to the straight finger line


def test_a_raised_arm_opens_more_than_a_hanging_one():
    hanging = swinging_body(np.zeros(1), 0.0)[0]
    raised = quat_identity((CANONICAL.num_joints,))  # T-pose: wrists at shoulder height
    open_hanging = settle(HandPose(FPS, config=STILL), hanging)
    open_raised = settle(HandPose(FPS, config=STILL), raised)
    assert (curl_depth_of(open_raised) < curl_depth_of(open_hanging)).all()


def test_openness_is_smoothed_not_a_jump():
    hands = HandPose(FPS, config=STILL)
    t = np.arange(40) / FPS
    bodies = swinging_body(t, 0.0)
    bodies[20:] = swinging_body(t[20:], 1.2)  # the arm starts swinging at frame 20
    steps = []
    for k, body in enumerate(bodies):
        before = hands.openness.copy()
        hands.append(body, t[k])
        steps.append(np.abs(hands.openness - before).max())
    assert max(steps) < 0.25 * STILL.max_open  # at most a quarter of the range per frame (time constant 0.25 s)


def test_deterministic_per_seed_and_reset_restarts_the_stream():
    t = np.arange(45) / FPS
    bodies = swinging_body(t, 0.5)

    def run(hands: HandPose) -> np.ndarray:
        return np.stack([hands.append(body, t[k]) for k, body in enumerate(bodies)])  # (T, 52, 4)

    a = HandPose(FPS, seed=4)
    first = run(a)
    a.reset()
    np.testing.assert_array_equal(run(a), first)
    np.testing.assert_array_equal(run(HandPose(FPS, seed=4)), first)
    other = run(HandPose(FPS, seed=5))
    assert np.abs(other[:, CANONICAL.num_joints:] - first[:, CANONICAL.num_joints:]).max() > 1e-3
    wobble = first[:, CANONICAL.num_joints:].std(axis=0).max()  # fingers move subtly even on a steady swing
    assert 1e-3 < wobble < 0.1
