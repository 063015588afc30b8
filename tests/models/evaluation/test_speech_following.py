"""Speech following: motion whose speed tracks the speech envelope scores high, at the right lag."""

import numpy as np
import pytest

from gesturecast.models.evaluation.speech_following import (
    frame_energy_db,
    lagged_correlations,
    moving_average,
    speech_following,
    upper_body_speed,
)
from gesturecast.models.motion.skeleton import CANONICAL

FPS = 30
RATE = 16000
SECONDS = 20


def bursty_speech(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Noise bursts of random length separated by silences → (audio (N,), per-frame loudness 0/1 (T,))."""
    rng = np.random.default_rng(seed)
    loud = np.zeros(SECONDS * FPS)
    frame = 0
    while frame < len(loud):
        length = int(rng.integers(10, 40))
        loud[frame : frame + length] = rng.random() < 0.5
        frame += length
    envelope = np.interp(np.arange(SECONDS * RATE), np.arange(len(loud)) * RATE / FPS, loud)
    audio = (0.001 + 0.3 * envelope) * rng.standard_normal(SECONDS * RATE)
    return audio.astype(np.float32), loud


def hand_motion(speed: np.ndarray) -> np.ndarray:
    """Rest-pose positions (T, J, 3) whose right hand moves along X with the given speed (m/s)."""
    positions = np.tile(CANONICAL.offsets.cumsum(axis=0)[None], (len(speed), 1, 1))  # any fixed pose
    positions[:, CANONICAL.index("RightHand"), 0] += np.cumsum(speed) / FPS
    return positions


def test_energy_is_rms_db_per_frame_with_floor():
    audio = np.concatenate([np.zeros(RATE), 0.1 * np.ones(RATE)]).astype(np.float32)
    energy = frame_energy_db(audio, RATE, FPS, 2 * FPS + 5, floor_db=-60.0)
    assert energy[:FPS - 1] == pytest.approx(-60.0)
    assert energy[FPS + 1 : 2 * FPS] == pytest.approx(-20.0)
    assert energy[2 * FPS :] == pytest.approx(-60.0)  # frames past the audio's end


def test_moving_average_keeps_constants_and_edges():
    assert moving_average(np.full(10, 3.0), 5) == pytest.approx(np.full(10, 3.0))


def test_lagged_correlation_finds_the_shift():
    rng = np.random.default_rng(1)
    signal = rng.standard_normal(300)
    delayed = np.concatenate([np.zeros(6), signal[:-6]])
    correlations = lagged_correlations(signal, delayed, 10)
    assert max(correlations, key=correlations.get) == 6
    assert correlations[6] == pytest.approx(1.0)


def test_motion_following_the_envelope_scores_high_at_its_delay():
    audio, loud = bursty_speech()
    delay = 6  # frames: the hand moves 0.2 s after the voice
    speed = 0.05 + 0.5 * np.concatenate([np.zeros(delay), loud[:-delay]])
    result = speech_following(hand_motion(speed), audio, RATE, FPS)
    assert result.best_correlation > 0.9
    assert result.best_lag_s == pytest.approx(delay / FPS, abs=2 / FPS)
    assert result.zero_lag_correlation < result.best_correlation


def test_motion_unrelated_to_the_speech_scores_low():
    audio, _ = bursty_speech(seed=2)
    _, other = bursty_speech(seed=3)
    result = speech_following(hand_motion(0.05 + 0.5 * other), audio, RATE, FPS)
    assert abs(result.zero_lag_correlation) < 0.4


def test_root_motion_does_not_count_as_gesture():
    positions = hand_motion(np.zeros(60))
    positions += np.arange(60)[:, None, None] * np.array([0.1, 0.0, 0.0])  # the whole body walks
    assert upper_body_speed(positions, FPS) == pytest.approx(np.zeros(60), abs=1e-9)
