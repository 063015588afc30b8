"""`gesturecast bench idle`: which frames count as a settled pause, and the idle's speed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gesturecast.realtime.pose.idle import IdleConfig
from gesturecast.tools.bench.idle import SETTLED_AFTER_S, idle_report, idle_speed, settled_frames

FPS = 30


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
