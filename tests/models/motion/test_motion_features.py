import numpy as np
import pytest

from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import (
    FEATURE_DIM,
    RootIntegrator,
    face_forward,
    facing_yaw,
    features_to_motion,
    mirror_motion,
    motion_to_features,
    speed_perturb,
    wrap_angle,
)
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_from_yaw, quat_mul
from gesturecast.models.motion.skeleton import NUM_JOINTS


def walking_motion(num_frames: int = 240, seed: int = 0) -> SkeletonMotion:
    """A turning, walking clip with smooth random joint rotations (several full turns of yaw)."""
    rng = np.random.default_rng(seed)
    t = np.arange(num_frames) / 30.0
    phases = rng.uniform(0, 2 * np.pi, size=(NUM_JOINTS, 3))
    axis_angle = 0.6 * np.sin(2.0 * t[:, None, None] + phases)  # (T, J, 3)
    rotations = quat_from_axis_angle(axis_angle)
    yaw = 1.5 + 2.5 * t  # turns past +-pi several times
    rotations[:, 0] = quat_mul(quat_from_yaw(yaw), rotations[:, 0])
    root = np.stack([np.cumsum(0.02 * np.sin(yaw)) + 3.0, 0.9 + 0.05 * np.sin(5 * t), np.cumsum(0.02 * np.cos(yaw))], 1)
    return SkeletonMotion(rotations, root)


def same_rotations(a: np.ndarray, b: np.ndarray, atol: float) -> bool:
    return bool(np.all(np.abs(np.abs(np.sum(a * b, axis=-1)) - 1.0) < atol))


def test_feature_shape_and_dtype():
    features = motion_to_features(walking_motion(50))
    assert features.shape == (50, FEATURE_DIM) and features.dtype == np.float32


def test_round_trip_reconstructs_rotations_and_trajectory():
    motion = walking_motion()
    yaw0 = float(facing_yaw(motion.rotations[0, 0]))
    start = (float(motion.root_position[0, 0]), float(motion.root_position[0, 2]))
    back = features_to_motion(motion_to_features(motion), start_position=start, start_yaw=yaw0)
    assert same_rotations(back.rotations, motion.rotations, 1e-5)
    np.testing.assert_allclose(back.root_position, motion.root_position, atol=1e-4)


def test_streaming_integrator_equals_offline_decoding():
    features = motion_to_features(walking_motion(120, seed=3))
    offline = features_to_motion(features, start_position=(0.5, -1.0), start_yaw=0.3)
    integrator = RootIntegrator((0.5, -1.0), 0.3)
    streamed = np.array([integrator.step(frame)[0] for frame in features])
    np.testing.assert_array_equal(streamed, offline.root_position)
    integrator.reset()
    assert np.array_equal(integrator.step(features[0])[0], offline.root_position[0])


def test_face_forward_starts_at_origin_facing_plus_z_and_keeps_features():
    motion = walking_motion()
    faced = face_forward(motion)
    assert abs(float(facing_yaw(faced.rotations[0, 0]))) < 1e-9
    np.testing.assert_allclose(faced.root_position[0, [0, 2]], 0.0, atol=1e-12)
    np.testing.assert_allclose(motion_to_features(faced), motion_to_features(motion), atol=1e-5)


def test_mirror_twice_is_exact_identity():
    motion = walking_motion()
    twice = mirror_motion(mirror_motion(motion))
    assert np.array_equal(twice.rotations, motion.rotations)
    assert np.array_equal(twice.root_position, motion.root_position)


def test_mirror_reflects_world_positions_and_swaps_sides():
    motion = walking_motion(20)
    positions = motion.positions()
    mirrored = mirror_motion(motion).positions()
    swap = motion.skeleton.mirror_indices()
    np.testing.assert_allclose(mirrored[:, swap] * [-1, 1, 1], positions, atol=1e-9)


def test_mirror_negates_yaw_rate_and_lateral_velocity():
    features = motion_to_features(walking_motion())
    mirrored = motion_to_features(mirror_motion(walking_motion()))
    np.testing.assert_allclose(mirrored[:, 3], -features[:, 3], atol=1e-5)
    np.testing.assert_allclose(mirrored[:, 1], -features[:, 1], atol=1e-5)
    np.testing.assert_allclose(mirrored[:, 2], features[:, 2], atol=1e-5)


@pytest.mark.parametrize("factor", [0.9, 1.1, 2.0])
def test_speed_perturb_length_and_timing(factor):
    motion = walking_motion(301)
    fast = speed_perturb(motion, factor)
    assert fast.num_frames == int(np.floor(300 / factor + 1e-9)) + 1
    assert same_rotations(fast.rotations[0], motion.rotations[0], 1e-12)
    # frame i samples source time i * factor; at integer source times it is exact
    step = 10
    source = int(round(step * factor))
    assert same_rotations(fast.rotations[step], motion.rotations[source], 1e-9)
    np.testing.assert_allclose(fast.root_position[step], motion.root_position[source], atol=1e-9)


def test_speed_perturb_rejects_non_positive_factor():
    with pytest.raises(ValueError):
        speed_perturb(walking_motion(10), 0.0)


def test_wrap_angle_range():
    angles = wrap_angle(np.linspace(-10, 10, 101))
    assert np.all(angles >= -np.pi) and np.all(angles < np.pi)
