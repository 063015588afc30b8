"""Cue placement on the latent grid: on time when known early, late by the wait otherwise, one gesture per part,
no repeat within the refractory time, ramped imposition weights."""

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.realtime.generation.gesture_cues import RAMP_LATENTS, Cue, CuePlan, GestureClip, ramp_weight

C = 8
D = 10
SECONDS_PER_LATENT = 4 / 30
ARMS = np.arange(C) < 4
TORSO = (np.arange(C) >= 4) & (np.arange(C) < 6)


def clip(name: str, channels: np.ndarray, length: int = 10, stroke: int = 4) -> GestureClip:
    latents = np.arange(length * C, dtype=np.float32).reshape(length, C)  # (N, C)
    features = np.arange(length * 4 * D, dtype=np.float32).reshape(length * 4, D)  # (N·d, D)
    return GestureClip(name, latents, channels, stroke, features, np.arange(D) < 3)


@pytest.fixture
def plan() -> CuePlan:
    return CuePlan({"wave": clip("wave", ARMS), "bow": clip("bow", ARMS | TORSO), "nod": clip("nod", TORSO)},
                   SECONDS_PER_LATENT)


def test_a_cue_known_early_puts_the_stroke_latent_on_the_word(plan):
    placement = plan.place(Cue("wave", time=3.0), next_latent=0)
    stroke_latent = placement.first + placement.clip.stroke_latent
    assert stroke_latent * SECONDS_PER_LATENT <= 3.0 < (stroke_latent + 1) * SECONDS_PER_LATENT
    assert placement.late_s == 0.0


def test_a_late_cue_starts_at_the_next_latent_and_says_how_late(plan):
    placement = plan.place(Cue("wave", time=1.0), next_latent=12)
    assert placement.first == 12
    assert placement.late_s == pytest.approx((12 + 4) * SECONDS_PER_LATENT - 1.0)


def test_one_gesture_per_body_part_and_no_repeat_within_the_refractory_time(plan):
    assert plan.place(Cue("wave", 3.0), 0) is not None
    assert plan.place(Cue("bow", 3.5), 0) is None  # shares the arms
    assert plan.place(Cue("nod", 3.5), 0) is not None  # the torso is free
    assert plan.place(Cue("wave", 5.0), 0) is None  # refractory
    assert plan.place(Cue("wave", 9.0), 0) is not None
    assert plan.dropped == 2


def test_imposition_holds_the_clip_latent_on_its_parts_with_ramped_weights(plan):
    placement = plan.place(Cue("wave", 3.0), 0)
    assert plan.imposition(placement.first - 1) is None
    imposed = plan.imposition(placement.first + 5)
    assert imposed.names == "wave"
    assert np.array_equal(imposed.target[ARMS], placement.clip.latents[5, ARMS]) and not imposed.weights[~ARMS].any()
    assert np.array_equal(imposed.pose[:, :3], placement.clip.features[20:24, :3])
    assert not imposed.pose_weights[:, 3:].any()
    decoded = np.zeros((4, D), np.float32)
    assert np.array_equal(imposed.blend(decoded)[:, :3], placement.clip.features[20:24, :3])  # weight 1 mid-clip
    ramp = [ramp_weight(k, 10) for k in range(10)]
    assert ramp[0] < ramp[1] < ramp[RAMP_LATENTS] == 1.0 == ramp[-RAMP_LATENTS - 1] > ramp[-1] > 0
    plan.forget_before(placement.last + 1)
    assert plan.placements == [] and plan.place(Cue("wave", 4.0), 0) is None  # still refractory


def test_an_unknown_gesture_is_one_line(plan):
    with pytest.raises(UserError, match="unknown gesture 'wav'; known: bow, nod, wave"):
        plan.place(Cue("wav", 1.0), 0)
