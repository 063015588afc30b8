"""Beat consistency: beats on onsets score 1, a σ offset scores exp(-1/2), ends are skipped."""

import numpy as np
import pytest

from gesturecast.models.evaluation.beat_consistency import (
    BeatConsistencyConfig,
    beat_alignment,
    beat_consistency,
    speech_onsets,
)
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.rotations import quat_identity
from gesturecast.models.motion.skeleton import CANONICAL

FPS = 30.0
DURATION_S = 12.0


def pulsing_motion(num_frames: int = int(DURATION_S * FPS)) -> np.ndarray:
    """T-pose gliding along +X with speed 1 + 0.5 cos(2πt): every joint slows down at t = k + 0.5 s."""
    t = np.arange(num_frames) / FPS
    x = t + 0.5 * np.sin(2 * np.pi * t) / (2 * np.pi)  # dx/dt = 1 + 0.5 cos(2πt)
    root = np.stack([x, np.full_like(t, CANONICAL.offsets[0, 1]), np.zeros_like(t)], axis=1)
    return SkeletonMotion(quat_identity((num_frames, CANONICAL.num_joints)), root).positions()


BEAT_TIMES = np.arange(0.5, DURATION_S, 1.0)  # the speed minima of pulsing_motion


def test_beats_exactly_on_onsets_score_one():
    assert beat_consistency(pulsing_motion(), FPS, BEAT_TIMES) == pytest.approx(1.0)


def test_onsets_one_sigma_from_every_beat_score_exp_minus_half():
    config = BeatConsistencyConfig()
    score = beat_consistency(pulsing_motion(), FPS, BEAT_TIMES + config.sigma_s, config)
    assert score == pytest.approx(np.exp(-0.5), rel=1e-9)


def test_onsets_in_the_skipped_ends_do_not_count():
    far_off_at_the_ends = np.concatenate([[0.2, 1.1], BEAT_TIMES, [DURATION_S - 0.3]])
    assert beat_consistency(pulsing_motion(), FPS, far_off_at_the_ends) == pytest.approx(1.0)


def test_a_frozen_pose_has_no_beats_and_scores_zero():
    frozen = np.repeat(pulsing_motion(1), int(DURATION_S * FPS), axis=0)
    assert beat_consistency(frozen, FPS, BEAT_TIMES) == 0.0


def test_beat_alignment_edge_cases():
    assert beat_alignment(np.array([1.0, 2.0]), np.array([1.0, 2.0, 5.0]), 0.3) == 1.0
    assert beat_alignment(np.array([1.0]), np.array([]), 0.3) == 0.0
    assert np.isnan(beat_alignment(np.array([]), np.array([1.0]), 0.3))


def test_speech_onsets_find_the_starts_of_tone_bursts():
    sample_rate = 16000
    audio = np.zeros(4 * sample_rate, dtype=np.float32)
    burst_times = np.array([0.5, 1.3, 2.1, 3.2])
    burst = np.sin(2 * np.pi * 440 * np.arange(sample_rate // 4) / sample_rate)  # 0.25 s, sharp attack
    burst *= np.minimum(1.0, np.arange(len(burst))[::-1] / 800)  # 50 ms fade-out: no second onset
    for t in burst_times:
        start = int(t * sample_rate)
        audio[start : start + len(burst)] = burst
    onsets = speech_onsets(audio, sample_rate)
    gaps = onsets[None, :] - burst_times[:, None]  # (bursts, onsets): onset time after each burst start
    assert (np.abs(gaps).min(axis=1) < 0.05).all()  # every burst found within ~1.5 hops of 32 ms
    assert ((gaps >= 0) & (gaps < 0.1)).any(axis=0).all()  # and every onset belongs to a burst's attack
