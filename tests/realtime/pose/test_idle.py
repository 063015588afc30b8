"""Idle motion: alive but calm, smooth, feet planted, deterministic under a seed."""

import numpy as np
import pytest

from gesturecast.models.motion.rotations import quat_conj, quat_mul, quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL, NUM_JOINTS
from gesturecast.realtime.pose.idle import IdleConfig, IdleMotion, relaxed_pose

FPS = 30.0
TIMES = np.arange(0.0, 30.0, 1.0 / FPS)  # (T,)


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle (degrees) between two quaternion arrays."""
    return np.degrees(np.linalg.norm(quat_to_axis_angle(quat_mul(a, quat_conj(b))), axis=-1))


@pytest.fixture(scope="module")
def idle_clip():
    idle = IdleMotion(seed=3)
    rotations = idle.rotations(TIMES)  # (T, J, 4)
    root = idle.root_position(TIMES)  # (T, 3)
    return idle, rotations, root, CANONICAL.forward_kinematics(rotations, root)[1]


def test_shapes_and_unit_quaternions(idle_clip):
    _, rotations, root, _ = idle_clip
    assert rotations.shape == (TIMES.size, NUM_JOINTS, 4)
    assert root.shape == (TIMES.size, 3)
    np.testing.assert_allclose(np.linalg.norm(rotations, axis=-1), 1.0, atol=1e-12)
    assert IdleMotion().rotations(1.25).shape == (NUM_JOINTS, 4)


def test_not_frozen_breathing_and_head_move(idle_clip):
    _, rotations, _, positions = idle_clip
    for joint in ("UpperChest", "Head", "Hips"):
        j = CANONICAL.index(joint)
        assert angle_deg(rotations[:, j], rotations[:1, j]).max() > 0.5
    head = positions[:, CANONICAL.index("Head")]  # (T, 3)
    assert np.ptp(head, axis=0).max() > 0.005  # head travels more than 5 mm


def test_not_wild_angles_speed_and_head_travel(idle_clip):
    idle, rotations, _, positions = idle_clip
    offsets = angle_deg(rotations, idle.base_rotations[None])  # (T, J)
    assert offsets.max() < 6.0
    per_frame = angle_deg(rotations[1:], rotations[:-1])  # (T-1, J)
    assert per_frame.max() < 0.3  # under 9 degrees per second on any joint
    head = positions[:, CANONICAL.index("Head")]
    assert np.ptp(head, axis=0).max() < 0.06


def test_feet_stay_planted(idle_clip):
    _, _, _, positions = idle_clip
    for foot in ("LeftFoot", "RightFoot"):
        assert np.ptp(positions[:, CANONICAL.index(foot)], axis=0).max() < 0.01


def test_deterministic_under_seed_and_seeds_differ():
    a = IdleMotion(seed=7).rotations(TIMES)
    np.testing.assert_array_equal(a, IdleMotion(seed=7).rotations(TIMES))
    assert angle_deg(a, IdleMotion(seed=8).rotations(TIMES)).max() > 0.2


def test_scalar_and_array_times_agree():
    idle = IdleMotion(seed=1)
    np.testing.assert_allclose(idle.rotations(TIMES)[45], idle.rotations(TIMES[45]), atol=1e-14)


def test_relaxed_pose_lowers_arms_beside_the_body():
    _, positions = CANONICAL.forward_kinematics(relaxed_pose(IdleConfig()))
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        hand = positions[CANONICAL.index(f"{side}Hand")]
        shoulder = positions[CANONICAL.index(f"{side}UpperArm")]
        assert hand[1] < shoulder[1] - 0.4  # well below the shoulder
        assert 0.0 < sign * hand[0] < 0.3  # on its own side, close to the body
        assert hand[2] > 0.0  # elbow bends forward


def test_zero_amplitudes_give_the_base_pose():
    still = IdleConfig(breath_deg=0.0, sway_deg=0.0, head_deg=0.0, arms_deg=0.0)
    idle = IdleMotion(still)
    np.testing.assert_allclose(idle.rotations(TIMES[:10]), np.broadcast_to(idle.base_rotations, (10, NUM_JOINTS, 4)))
