"""`gesturecast bench idle`: which frames count as a settled pause, and the idle's speed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.realtime.pose.idle import IdleConfig, IdleMotion
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.tools.bench.idle import (
    SETTLED_AFTER_S,
    avatar_rest,
    idle_report,
    idle_speed,
    real_take,
    settled_frames,
)

FPS = 30


def speech_pause_speech(pause_s: float) -> np.ndarray:
    """0.5 s of silence, 2 s of the packaged sample's speech, ``pause_s`` of silence, the same 2 s: (N,) float32."""
    speech = load_audio(PACKAGED_SAMPLE)[int(0.6 * SAMPLE_RATE): int(2.6 * SAMPLE_RATE)]  # voiced throughout
    lead, pause = np.zeros(SAMPLE_RATE // 2, np.float32), np.zeros(int(pause_s * SAMPLE_RATE), np.float32)
    return np.concatenate([lead, speech, pause, speech])


def moving_only_while_speaking(audio: np.ndarray) -> SkeletonMotion:
    """The idle motion, frozen from 0.5 s into the silence between the two sentences to just after its end."""
    frames = len(audio) * FPS // SAMPLE_RATE
    times = np.arange(frames) / FPS  # (T,)
    silent = (times >= 3.0) & (times < len(audio) / SAMPLE_RATE - 1.9)  # into the second sentence
    times[silent] = 3.0  # the pose of 3 s held
    idle = IdleMotion(seed=0)
    return SkeletonMotion(idle.rotations(times), idle.root_position(times), FPS, CANONICAL)


def test_only_long_pauses_settle_and_only_after_their_first_moments():
    speaking = np.concatenate([np.ones(30), np.zeros(90), np.ones(30), np.zeros(45), np.ones(10)]).astype(bool)
    settled = settled_frames(speaking, FPS)
    start = 30 + int(SETTLED_AFTER_S * FPS)
    assert np.flatnonzero(settled).tolist() == list(range(start, 120))  # the 3 s pause, not the 1.5 s one


def test_a_pause_at_the_end_of_the_take_settles_too():
    speaking = np.concatenate([np.ones(10), np.zeros(100)]).astype(bool)
    assert settled_frames(speaking, FPS).sum() == 100 - int(SETTLED_AFTER_S * FPS)


def test_the_idle_speed_grows_with_its_amplitudes_and_is_zero_without_them():
    config = IdleConfig()
    doubled = replace(config, breath_deg=2 * config.breath_deg, sway_deg=2 * config.sway_deg,
                      head_deg=2 * config.head_deg, arms_deg=2 * config.arms_deg)
    still = replace(config, breath_deg=0.0, sway_deg=0.0, head_deg=0.0, arms_deg=0.0)
    base = idle_speed(config, seconds=20.0)
    assert idle_speed(doubled, seconds=20.0) == pytest.approx(2 * base, rel=0.03)
    assert idle_speed(still, seconds=20.0) == pytest.approx(0.0, abs=1e-9)


def test_the_report_pools_takes_by_their_settled_seconds():
    takes = {"a": {"settled_m_s": 0.01, "settled_s": 30.0}, "b": {"settled_m_s": 0.04, "settled_s": 10.0}}
    report = idle_report(takes, idle=0.025)
    assert report["real_settled_m_s"] == {"pooled_by_time": 0.0175, "mean_of_takes": 0.025}
    assert report["real_over_idle"] == {"pooled_by_time": 0.7, "mean_of_takes": 1.0}


def test_a_body_that_stops_in_long_pauses_reads_no_settled_motion_and_rests():
    audio = speech_pause_speech(5.0)
    take = real_take(moving_only_while_speaking(audio), audio, len(audio) * FPS // SAMPLE_RATE)
    assert take["settled_m_s"] == 0.0 and take["settled_over_speaking"] == 0.0
    assert take["settled_s"] > 2.0 and take["speaking_m_s"] > 0.0
    assert 0.0 <= take["rest"] < 0.3  # the pause still holds the hangover's moving frames


def test_a_take_without_a_long_pause_has_no_settled_speed_and_alone_is_a_clear_error():
    audio = speech_pause_speech(1.0)
    take = real_take(moving_only_while_speaking(audio), audio, len(audio) * FPS // SAMPLE_RATE)
    assert take["settled_m_s"] is None and take["settled_s"] == 0.0
    with pytest.raises(UserError, match="long enough to settle"):
        idle_report({"short": take}, idle=0.01)


def test_the_avatars_rest_is_read_per_seed_on_the_same_audio(tiny_model):
    _, bundle_dir = tiny_model
    rest = avatar_rest(load_bundle(bundle_dir), speech_pause_speech(3.0), [0, 1])
    assert len(rest["per_seed"]) == 2 and all(np.isfinite(rest["per_seed"]))
    assert rest["mean"] == pytest.approx(np.mean(rest["per_seed"]), abs=1e-3)
