"""Ramps reach their endpoints smoothly and monotonically; pose cross-fades slerp with the weight."""

import numpy as np
import pytest

from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_to_axis_angle
from gesturecast.models.motion.skeleton import NUM_JOINTS
from gesturecast.realtime.pose.transitions import PoseCrossfade, Ramp, blend_poses, smoothstep


def test_smoothstep_endpoints_midpoint_and_clipping():
    assert smoothstep(0.0) == 0.0
    assert smoothstep(1.0) == 1.0
    assert smoothstep(0.5) == pytest.approx(0.5)
    assert smoothstep(-3.0) == 0.0
    assert smoothstep(7.0) == 1.0


def test_vector_ramp_hits_endpoints_and_is_monotone_per_component():
    start, target = np.array([0.0, 1.0, -2.0]), np.array([1.0, -1.0, 2.0])
    ramp = Ramp(start, duration_s=0.4)
    ramp.set_target(target, t=10.0)
    np.testing.assert_array_equal(ramp.value(10.0), start)
    np.testing.assert_array_equal(ramp.value(10.4), target)
    np.testing.assert_array_equal(ramp.value(99.0), target)
    times = np.linspace(10.0, 10.4, 41)
    values = np.stack([ramp.value(t) for t in times])  # (41, 3)
    steps = np.diff(values, axis=0) * np.sign(target - start)
    assert np.all(steps >= 0.0)
    assert np.all(np.abs(np.diff(values, axis=0)).max(axis=0) < 0.1 * np.abs(target - start))
    assert ramp.done(10.4) and not ramp.done(10.2)


def test_retarget_mid_ramp_continues_from_the_current_value():
    ramp = Ramp(0.0, duration_s=1.0)
    ramp.set_target(1.0, t=0.0)
    shown = ramp.value(0.5)
    ramp.set_target(-1.0, t=0.5)
    assert ramp.value(0.5) == pytest.approx(shown)
    assert ramp.value(1.5) == pytest.approx(-1.0)


def test_zero_duration_jumps_and_shape_mismatch_is_refused():
    ramp = Ramp(np.zeros(2), duration_s=0.0)
    ramp.set_target([3.0, 4.0], t=1.0)
    np.testing.assert_array_equal(ramp.value(1.0), [3.0, 4.0])
    with pytest.raises(ValueError):
        ramp.set_target([1.0, 2.0, 3.0], t=2.0)


def pose(angle: float) -> np.ndarray:
    return quat_from_axis_angle(np.tile([angle, 0.0, 0.0], (NUM_JOINTS, 1)))  # (J, 4)


def test_blend_poses_interpolates_angle_and_root():
    rotations, root = blend_poses(pose(0.0), np.zeros(3), pose(0.8), np.array([0.0, 0.0, 2.0]), 0.25)
    np.testing.assert_allclose(quat_to_axis_angle(rotations)[:, 0], 0.2, atol=1e-12)
    np.testing.assert_allclose(root, [0.0, 0.0, 0.5])


def test_crossfade_into_speech_and_back():
    fade = PoseCrossfade(duration_s=0.5)
    idle, speech = pose(0.0), pose(1.0)
    root = np.zeros(3)
    np.testing.assert_allclose(fade.mix(0.0, idle, root, speech, root)[0], idle)
    fade.fade_to(1.0, t=1.0)
    fade.fade_to(1.0, t=1.2)  # repeated request does not restart the fade
    assert fade.weight(1.25) == pytest.approx(0.5)
    np.testing.assert_allclose(fade.mix(1.5, idle, root, speech, root)[0], speech, atol=1e-12)
    weights = [fade.weight(t) for t in np.linspace(1.0, 1.5, 11)]
    assert np.all(np.diff(weights) >= 0.0)
    fade.fade_to(0.0, t=2.0)
    assert fade.weight(2.5) == pytest.approx(0.0)
    with pytest.raises(ValueError):
        fade.fade_to(1.5, t=3.0)
