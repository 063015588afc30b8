"""Kinematic metrics on constructed motion with known answers."""

import numpy as np
import pytest

from gesturecast.models.evaluation.metrics import acceleration, jerk, l1_diversity, liveliness, seed_diversity

FPS = 30.0
RNG = np.random.default_rng(0)


def polynomial_clip(coefficients: np.ndarray, num_frames: int = 40) -> np.ndarray:
    """Every joint follows p(t) = Σ_k c_k t^k per axis. coefficients: (K, J, 3) -> positions (T, J, 3)."""
    t = np.arange(num_frames) / FPS
    powers = t[:, None] ** np.arange(len(coefficients))[None, :]  # (T, K)
    return np.einsum("tk,kjd->tjd", powers, coefficients)


def test_constant_pose_has_zero_jerk_acceleration_and_liveliness():
    pose = np.repeat(RNG.normal(size=(1, 5, 3)), 20, axis=0)
    real = pose + 0.05 * RNG.normal(size=pose.shape)
    assert jerk(pose, FPS) == 0.0 and acceleration(pose, FPS) == 0.0
    lively = liveliness(pose, real, FPS)
    assert lively.speed_ratio == 0.0 and lively.variance_ratio == 0.0


def test_cubic_trajectory_has_its_exact_jerk_and_quadratic_its_exact_acceleration():
    direction = np.array([[2.0, -1.0, 2.0]]) / 3.0  # unit vector
    cubic = polynomial_clip(np.stack([np.zeros((1, 3)), np.ones((1, 3)), np.zeros((1, 3)), 1.5 * direction]))
    assert jerk(cubic, FPS) == pytest.approx(6 * 1.5, rel=1e-6)  # d³/dt³ (1.5 t³) = 9 m/s³
    quadratic = polynomial_clip(np.stack([np.zeros((1, 3)), np.ones((1, 3)), 0.5 * 4.0 * direction]))
    assert acceleration(quadratic, FPS) == pytest.approx(4.0, rel=1e-6)
    assert jerk(quadratic, FPS) == pytest.approx(0.0, abs=1e-6)


def test_liveliness_of_real_motion_against_itself_and_a_scaled_copy():
    real = np.cumsum(RNG.normal(size=(60, 4, 3)), axis=0) * 0.01
    same = liveliness(real, real, FPS)
    assert same.speed_ratio == pytest.approx(1.0) and same.variance_ratio == pytest.approx(1.0)
    faster = liveliness(2.0 * real, real, FPS)  # twice the displacement per frame
    assert faster.speed_ratio == pytest.approx(2.0) and faster.variance_ratio == pytest.approx(4.0)
    with pytest.raises(ValueError, match="does not move"):
        liveliness(real, np.zeros_like(real), FPS)


def test_diversity_definitions():
    clip = RNG.normal(size=(30, 6, 3))
    assert l1_diversity(np.repeat(clip[:1], 30, axis=0)) == pytest.approx(0.0, abs=1e-12)
    translated = clip + np.arange(30)[:, None, None]  # root translation is not diversity
    assert l1_diversity(translated) == pytest.approx(l1_diversity(clip))
    two_frames = np.zeros((2, 2, 3))
    two_frames[1, 1, 0] = 2.0  # one coordinate moves by 2: |dev| = 1 in each frame
    assert l1_diversity(two_frames) == pytest.approx(1.0)
    offset = np.zeros((3, 30, 6, 3))
    offset[1, :, 1:, 0] = 0.3  # clip 1 differs by 0.3 m on 5 of 6 joints
    assert seed_diversity(offset + clip) == pytest.approx((0.25 + 0.25 + 0.0) / 3)
    assert seed_diversity(np.stack([clip, clip])) == 0.0
