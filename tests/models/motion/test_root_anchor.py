"""The avatar stays where it stands: bounded / locked / free root integration (realtime/root_anchor.py)."""

import math

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.motion_features import (
    FEATURE_DIM,
    ROOT_VELOCITY,
    ROOT_YAW_RATE,
    RootIntegrator,
)
from gesturecast.models.motion.root_anchor import (
    RootAnchor,
    RootBounds,
    RootMode,
    RootTravel,
    parse_root_mode,
    saturate,
)

FPS = 30.0


def root_features(velocity_xz: np.ndarray, yaw_rate: np.ndarray, height: float = 0.9) -> np.ndarray:
    """Feature frames (T, D) carrying only root channels: planar velocity (T, 2) and yaw rate (T,)."""
    features = np.zeros((len(yaw_rate), FEATURE_DIM))
    features[:, 0] = height
    features[:, ROOT_VELOCITY] = velocity_xz
    features[:, ROOT_YAW_RATE] = yaw_rate[:, None]
    return features


def walk_and_turn(seconds: float, speed: float = 1.0, turn_deg_per_s: float = 30.0) -> np.ndarray:
    frames = int(seconds * FPS)
    velocity = np.tile([0.0, speed / FPS], (frames, 1))  # forward, metres per frame
    return root_features(velocity, np.full(frames, math.radians(turn_deg_per_s) / FPS))


def run(anchor: RootAnchor, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    steps = [anchor.step(frame) for frame in features]
    return np.stack([p for p, _ in steps]), np.array([y for _, y in steps])  # (T, 3), (T,)


def test_free_is_the_plain_integration():
    features = walk_and_turn(20.0)
    positions, yaws = run(RootAnchor(RootMode.FREE, fps=FPS), features)
    integrator = RootIntegrator()
    expected = [integrator.step(frame) for frame in features]
    np.testing.assert_allclose(positions, np.stack([p for p, _ in expected]), atol=1e-9)
    np.testing.assert_allclose(yaws, [y for _, y in expected], atol=1e-9)


def test_bounded_keeps_a_walking_turning_avatar_in_place_for_ten_minutes():
    bounds = RootBounds()
    positions, yaws = run(RootAnchor(RootMode.BOUNDED, bounds, FPS), walk_and_turn(600.0, speed=1.5))
    distance = np.linalg.norm(positions[:, [0, 2]], axis=1)
    assert distance.max() <= bounds.radius_m + 1e-12
    assert np.abs(np.degrees(yaws)).max() <= bounds.max_yaw_deg
    np.testing.assert_allclose(positions[:, 1], 0.9)  # height untouched


def test_bounded_never_moves_faster_than_the_generated_motion_plus_the_recentering():
    """No pop at the bound: the saturation is 1-Lipschitz, so each frame's step is at most the input's
    step plus the leak's pull (``(1 - leak) · state``), which stays small."""
    features = walk_and_turn(120.0, speed=2.0, turn_deg_per_s=90.0)
    free_positions, _ = run(RootAnchor(RootMode.FREE, fps=FPS), features)
    positions, yaws = run(RootAnchor(RootMode.BOUNDED, fps=FPS), features)
    step = np.linalg.norm(np.diff(positions[:, [0, 2]], axis=0), axis=1)
    free_step = np.linalg.norm(np.diff(free_positions[:, [0, 2]], axis=0), axis=1)
    assert step.max() <= free_step.max() * 1.05
    assert np.abs(np.diff(yaws)).max() <= math.radians(90.0) / FPS * 1.05


def test_small_sways_pass_almost_unchanged():
    t = np.arange(int(10 * FPS)) / FPS
    sway = 0.02 * np.sin(2 * np.pi * 0.5 * t)  # ±2 cm side to side
    velocity = np.stack([np.gradient(sway), np.zeros_like(t)], axis=1)
    features = root_features(velocity, np.zeros_like(t))
    free_positions, _ = run(RootAnchor(RootMode.FREE, fps=FPS), features)
    positions, _ = run(RootAnchor(RootMode.BOUNDED, fps=FPS), features)
    settled = slice(int(4 * FPS), None)  # after the first two sway cycles
    swing = np.ptp(positions[settled, 0])
    assert 0.9 * np.ptp(free_positions[settled, 0]) < swing <= np.ptp(free_positions[settled, 0])


def test_locked_pins_position_and_facing():
    positions, yaws = run(RootAnchor(RootMode.LOCKED, fps=FPS), walk_and_turn(10.0))
    np.testing.assert_array_equal(positions[:, [0, 2]], 0.0)
    np.testing.assert_array_equal(yaws, 0.0)


def test_a_mode_change_reanchors_where_the_avatar_stands():
    anchor = RootAnchor(RootMode.FREE, fps=FPS)
    features = walk_and_turn(10.0)
    before, _ = run(anchor, features)
    anchor.set_mode(RootMode.BOUNDED)
    after, _ = run(anchor, features)
    assert np.linalg.norm(after[0, [0, 2]] - before[-1, [0, 2]]) < 1.0 / FPS * 1.01  # one frame's walk at most
    assert np.linalg.norm(after[:, [0, 2]] - before[-1, [0, 2]], axis=1).max() <= RootBounds().radius_m + 1e-12


def test_saturation_bounds_and_keeps_direction():
    offsets = np.array([[0.0, 0.0], [0.01, 0.0], [3.0, 4.0]])
    out = saturate(offsets, 0.15)
    assert np.linalg.norm(out, axis=1).max() <= 0.15 + 1e-12
    np.testing.assert_allclose(out[2] / np.linalg.norm(out[2]), [0.6, 0.8])
    np.testing.assert_array_equal(out[0], 0.0)


def test_unknown_mode_is_one_line():
    assert parse_root_mode("locked") is RootMode.LOCKED
    with pytest.raises(UserError, match="unknown root mode 'pinned': choose one of bounded, free, locked"):
        parse_root_mode("pinned")


def test_root_travel_reports_the_farthest_point_the_end_point_and_the_widest_turn():
    travel = RootTravel()
    path = [((1.0, 0.9, 2.0), 0.5), ((1.3, 0.9, 2.0), 0.5 + math.radians(90)),
            ((1.1, 0.9, 2.0), 0.5 + math.radians(200))]  # out 0.3 m, back to 0.1 m; 200° is 160° the other way
    for position, yaw in path:
        travel.update(np.array(position), yaw)
    assert travel.max_distance_m == pytest.approx(0.3)
    assert travel.net_travel_m == pytest.approx(0.1)
    assert travel.max_facing_deg == pytest.approx(160.0)


def test_root_travel_of_a_bounded_walk_stays_inside_the_bounds():
    bounds = RootBounds()
    positions, yaws = run(RootAnchor(RootMode.BOUNDED, bounds, FPS), walk_and_turn(20.0))
    travel = RootTravel()
    for position, yaw in zip(positions, yaws, strict=True):
        travel.update(position, yaw)
    assert 0.5 * bounds.radius_m < travel.max_distance_m < bounds.radius_m
    assert 0.5 * bounds.max_yaw_deg < travel.max_facing_deg < bounds.max_yaw_deg
    assert travel.net_travel_m <= travel.max_distance_m
