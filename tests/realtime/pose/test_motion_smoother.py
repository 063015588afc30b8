"""Streaming motion smoothing (realtime/pose/motion_smoother.py): chunk invariance, edges, frequency response."""

import numpy as np
import pytest

from gesturecast.realtime.pose.motion_smoother import MotionSmoother, binomial_weights

FPS = 30.0


def smooth_in_chunks(features: np.ndarray, half_width: int, chunk: int) -> np.ndarray:
    smoother = MotionSmoother(half_width)
    parts = [smoother.push(features[i: i + chunk]) for i in range(0, len(features), chunk)]
    return np.concatenate([*parts, smoother.flush(features.shape[1])])


@pytest.mark.parametrize("chunk", [1, 3, 4, 7, 100])
def test_any_chunking_gives_the_same_frames(chunk):
    features = np.random.default_rng(0).standard_normal((50, 6))
    np.testing.assert_array_equal(smooth_in_chunks(features, 2, chunk), smooth_in_chunks(features, 2, 50))


def test_frames_leave_k_frames_late_and_all_of_them_leave():
    smoother = MotionSmoother(2)
    assert smoother.push(np.zeros((4, 3))).shape == (2, 3)
    assert smoother.push(np.zeros((4, 3))).shape == (4, 3)
    assert smoother.flush(3).shape == (2, 3)


def test_interior_frames_are_the_binomial_window_and_edges_renormalise():
    features = np.random.default_rng(1).standard_normal((12, 2))
    out = smooth_in_chunks(features, 2, 4)
    np.testing.assert_allclose(binomial_weights(2), [1 / 16, 4 / 16, 6 / 16, 4 / 16, 1 / 16])
    np.testing.assert_allclose(out[5], binomial_weights(2) @ features[3:8])
    np.testing.assert_allclose(out[0], np.array([6, 4, 1]) @ features[:3] / 11)
    np.testing.assert_allclose(out[-1], np.array([1, 4, 6]) @ features[-3:] / 11)


def test_constants_pass_unchanged_and_zero_width_is_the_identity():
    constant = np.tile([0.3, -1.0], (9, 1))
    np.testing.assert_allclose(smooth_in_chunks(constant, 3, 2), constant)
    features = np.random.default_rng(2).standard_normal((9, 2))
    np.testing.assert_array_equal(smooth_in_chunks(features, 0, 4), features)


def test_gain_keeps_gestures_and_removes_the_latent_step():
    t = np.arange(600) / FPS

    def gain(hz: float) -> float:
        wave = np.sin(2 * np.pi * hz * t)[:, None]
        return np.ptp(smooth_in_chunks(wave, 2, 4)[100:-100]) / np.ptp(wave[100:-100])

    assert gain(2.0) == pytest.approx(np.cos(np.pi * 2.0 / FPS) ** 4, abs=0.01)
    assert gain(7.5) == pytest.approx(0.25, abs=0.01)
