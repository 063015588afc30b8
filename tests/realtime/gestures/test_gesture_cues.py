"""Cue placement on the latent grid: on time when known early, a quicker approach when late, blended with a gesture
playing on shared parts, merged into the same gesture, dropped only with a log line, and every outcome counted."""

import logging
from types import SimpleNamespace

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.realtime.gestures.cues import (
    BLEND_LATENTS,
    HOLD_LATENTS,
    RAMP_LATENTS,
    Cue,
    CuePlan,
    GestureClip,
    ramp_weight,
)

C = 8
D = 10
SECONDS_PER_LATENT = 4 / 30
ARMS = np.arange(C) < 4
TORSO = (np.arange(C) >= 4) & (np.arange(C) < 6)
LEGS = np.arange(C) >= 6


def clip(name: str, channels: np.ndarray, length: int = 10, stroke: int = 4, columns: int = 3,
         release: int = -1) -> GestureClip:
    latents = np.arange(length * C, dtype=np.float32).reshape(length, C)  # (N, C)
    features = np.arange(length * 4 * D, dtype=np.float32).reshape(length * 4, D)  # (N·d, D)
    return GestureClip(name, latents, channels, stroke, features, np.arange(D) < columns, release_latent=release)


@pytest.fixture
def plan() -> CuePlan:
    return CuePlan({"wave": clip("wave", ARMS), "raise": clip("raise", ARMS),
                    "bow": clip("bow", ARMS | TORSO, length=24, stroke=8, columns=6),
                    "guide": clip("guide", ARMS | TORSO, length=12, stroke=5, columns=6),
                    "call": clip("call", ARMS | TORSO | LEGS, length=16, stroke=6, columns=8)}, SECONDS_PER_LATENT)


def at(latent: float) -> float:
    """The stream time inside latent ``latent``."""
    return (latent + 0.5) * SECONDS_PER_LATENT


def test_a_cue_known_early_puts_the_stroke_latent_on_the_word(plan):
    outcome = plan.place(Cue("wave", time=3.0), next_latent=0)
    (placement,) = plan.placements
    assert placement.stroke * SECONDS_PER_LATENT <= 3.0 < (placement.stroke + 1) * SECONDS_PER_LATENT
    assert outcome.status == "on time" and outcome.stroke_time == placement.stroke * SECONDS_PER_LATENT
    assert placement.start == placement.first and placement.ramp_in == RAMP_LATENTS


def test_a_late_cue_skips_the_clip_opening_and_says_how_late(plan):
    outcome = plan.place(Cue("wave", time=at(10)), next_latent=9)
    (placement,) = plan.placements
    assert placement.start == 9 and placement.stroke == 9 + BLEND_LATENTS  # a quicker approach, not the whole clip
    assert outcome.status == "late" and outcome.stroke_time - outcome.cue.time == pytest.approx(
        (12 - 10.5) * SECONDS_PER_LATENT)
    assert placement.weight(placement.stroke) == 1.0


def test_the_same_gesture_over_its_word_is_merged_into_the_one_playing(plan):
    plan.place(Cue("wave", at(20)), 0)
    outcome = plan.place(Cue("wave", at(22), "welcome"), 0)
    assert outcome.status == "merged" and len(plan.placements) == 1


def test_a_gesture_close_after_another_on_the_same_parts_cuts_its_return_short(plan):
    plan.place(Cue("wave", at(20)), 0)
    outcome = plan.place(Cue("raise", at(22)), 0)
    wave, raise_ = plan.placements
    assert outcome.status == "blended"
    assert raise_.start == wave.stroke + 1 and raise_.stroke == raise_.start + BLEND_LATENTS  # moved 2 latents
    assert wave.stop == raise_.start + BLEND_LATENTS - 1 and wave.weight(wave.stroke) == 1.0
    assert outcome.stroke_time - outcome.cue.time <= 0.6
    imposed = plan.imposition(wave.stop)  # both cross-fading: weights add up to at most 1
    assert imposed.names == "wave+raise" and imposed.weights[ARMS].max() <= 1.0 and not imposed.weights[~ARMS].any()


def test_a_bow_after_a_wave_bows_on_time_and_takes_the_arms_after_the_wave_held_its_stroke(plan):
    plan.place(Cue("wave", at(20)), 0)
    outcome = plan.place(Cue("bow", at(22), "thanks"), 0)
    (wave,) = [p for p in plan.placements if p.cue.gesture == "wave"]
    bow_arms, bow_torso = sorted((p for p in plan.placements if p.cue.gesture == "bow"), key=lambda p: p.start)[::-1]
    assert outcome.status == "blended" and outcome.stroke_time == bow_torso.stroke * SECONDS_PER_LATENT
    assert bow_torso.stroke == 22 and np.array_equal(bow_torso.clip.channels, TORSO)
    assert bow_arms.start == wave.stroke + HOLD_LATENTS and np.array_equal(bow_arms.clip.channels, ARMS)
    assert plan.imposition(21).names == "wave+bow"


def placed(plan: CuePlan, gesture: str) -> list:
    """The placements of ``gesture``, in order of their start."""
    return sorted((p for p in plan.placements if p.cue.gesture == gesture), key=lambda p: p.start)


def test_a_guide_after_a_bow_shared_with_a_wave_cuts_both_bow_placements_and_plays_on_its_word(plan):
    plan.place(Cue("wave", at(20)), 0)
    plan.place(Cue("bow", at(22), "thanks"), 0)  # its torso on time, its arms from latent 26
    outcome = plan.place(Cue("guide", at(33), "this is"), 0)
    (guide,) = placed(plan, "guide")
    assert outcome.status == "blended" and guide.stroke == 33
    assert outcome.note == "after the bow, whose return is cut short"
    assert [p.stop for p in placed(plan, "bow")] == [guide.start + BLEND_LATENTS - 1] * 2  # the torso and the arms
    assert plan.imposition(guide.start).names == "bow+guide"
    assert plan.imposition(guide.start + BLEND_LATENTS).names == "guide"


def test_a_bow_part_that_would_take_the_arms_only_after_the_next_gesture_begins_is_taken_out(plan):
    plan.place(Cue("wave", at(20)), 0)
    plan.place(Cue("bow", at(22), "thanks"), 0)
    assert placed(plan, "bow")[1].start == 20 + HOLD_LATENTS
    outcome = plan.place(Cue("guide", at(28), "meet"), 0)  # its approach starts at 23, before the bow's arms would
    (guide,) = placed(plan, "guide")
    (bow_torso,) = placed(plan, "bow")
    assert outcome.status == "blended" and guide.stroke == 28 and guide.start == 23
    assert np.array_equal(bow_torso.clip.channels, TORSO) and bow_torso.stop == 23 + BLEND_LATENTS - 1
    assert all(plan.imposition(k).names in ("wave+bow+guide", "bow+guide", "guide") for k in range(23, 26))


def test_a_call_after_a_shared_bow_moves_its_legs_on_time_and_takes_the_rest_from_both_bow_placements(plan):
    plan.place(Cue("wave", at(20)), 0)
    plan.place(Cue("bow", at(22), "thanks"), 0)
    outcome = plan.place(Cue("call", at(40), "come here"), 0)
    legs, rest = sorted(placed(plan, "call"), key=lambda p: p.clip.channels.sum())
    assert outcome.status == "blended" and outcome.stroke_time == 40 * SECONDS_PER_LATENT
    assert np.array_equal(legs.clip.channels, LEGS) and np.array_equal(rest.clip.channels, ARMS | TORSO)
    assert legs.start == 34 and rest.start == 34 and rest.ramp_in == BLEND_LATENTS
    assert [p.stop for p in placed(plan, "bow")] == [34 + BLEND_LATENTS - 1] * 2


def test_a_wave_that_meets_the_arms_of_a_shared_call_ends_every_part_of_the_call_at_once(plan):
    plan.place(Cue("guide", at(20), "this is"), 0)
    plan.place(Cue("call", at(24), "come here"), 0)  # its legs on time, the arms and torso from latent 26
    outcome = plan.place(Cue("wave", at(34), "bye"), 0)  # meets the arms only
    legs, rest = sorted(placed(plan, "call"), key=lambda p: p.clip.channels.sum())
    assert outcome.status == "blended" and np.array_equal(legs.clip.channels, LEGS)
    assert legs.stop == rest.stop == 30 + BLEND_LATENTS - 1  # the whole call gives way, not its arms alone


def test_a_cue_with_no_room_is_dropped_with_a_log_line_and_counted(plan, caplog):
    plan.place(Cue("wave", at(20)), 0)
    with caplog.at_level(logging.WARNING):
        outcome = plan.place(Cue("raise", at(19), "yay"), 0)  # its stroke before the wave's, on the same arms
    assert outcome.status == "dropped" and outcome.stroke_time is None
    assert "gesture raise (yay) dropped" in caplog.text
    assert plan.summary() == {"on time": 1, "late": 0, "blended": 0, "merged": 0, "dropped": 1}


def test_imposition_holds_the_clip_latent_on_its_parts_with_ramped_weights(plan):
    plan.place(Cue("wave", 3.0), 0)
    (placement,) = plan.placements
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
    assert [placement.weight(placement.first + k) for k in range(10)] == pytest.approx(ramp)
    plan.forget_before(placement.last + 1)
    assert plan.placements == []


def test_an_unknown_gesture_is_one_line(plan):
    with pytest.raises(UserError, match="unknown gesture 'wav'; known: bow, call, guide, raise, wave"):
        plan.place(Cue("wav", 1.0), 0)


def test_performances_play_in_turn_so_two_plays_differ():
    versions = (clip("wave", ARMS, length=10), clip("wave", ARMS, length=12, stroke=5))
    plan = CuePlan({"wave": versions[0]}, SECONDS_PER_LATENT, {"wave": versions})
    plan.place(Cue("wave", at(20)), 0)
    plan.place(Cue("wave", at(60)), 0)
    plan.place(Cue("wave", at(100)), 0)
    assert [p.clip for p in plan.placements] == [versions[0], versions[1], versions[0]]


@pytest.fixture
def held() -> CuePlan:
    """A wave that holds its stroke from latent 4 to its release at 15 and returns over its last 4 latents."""
    return CuePlan({"wave": clip("wave", ARMS, length=20, stroke=4, release=15),
                    "raise": clip("raise", ARMS, length=8, stroke=3, release=5)}, SECONDS_PER_LATENT)


def test_a_gesture_well_after_a_long_hold_cuts_the_hold_short_and_plays_the_whole_return_before_it(held):
    held.place(Cue("wave", at(20)), 0)  # stroke 20, clip latents 16 … 35
    outcome = held.place(Cue("raise", at(36), "yay"), 0)  # its approach from 33, on time
    head, moved = placed(held, "wave")
    (raise_,) = placed(held, "raise")
    assert outcome.status == "blended" and raise_.stroke == 36 and raise_.start == raise_.first == 33
    assert outcome.note == "after the wave, whose hold is cut short"
    assert moved.skip == 2 and moved.stop == raise_.start and moved.clip_latent(moved.stop) == 19  # arms down on it
    assert moved.clip_latent(moved.start + BLEND_LATENTS - 1) == 15 and head.stop == moved.start + BLEND_LATENTS - 1
    assert moved.stroke == head.stroke == 20 and not moved.whole
    assert np.array_equal(held.imposition(31).target[ARMS], moved.clip.latents[17, ARMS])  # the return alone


def test_a_gesture_too_soon_after_a_stroke_to_move_the_return_cuts_the_return_as_before(held):
    held.place(Cue("wave", at(20)), 0)
    outcome = held.place(Cue("raise", at(30), "yay"), 0)  # the return would begin 1 latent after the stroke's hold
    (wave,) = placed(held, "wave")
    assert outcome.note == "after the wave, whose return is cut short" and wave.stop == 27 + BLEND_LATENTS - 1


def test_a_return_is_never_moved_into_latents_already_generated(held):
    held.place(Cue("wave", at(20)), 0)
    outcome = held.place(Cue("raise", at(36), "yay"), next_latent=28)  # the return would begin at 27
    (wave,) = placed(held, "wave")
    assert outcome.note == "after the wave, whose return is cut short" and wave.stop == 33 + BLEND_LATENTS - 1


def test_the_same_gesture_on_a_word_during_the_playing_ones_return_plays_again_instead_of_merging(held):
    held.place(Cue("wave", at(20)), 0)
    assert held.place(Cue("wave", at(26), "welcome"), 0).status == "merged"  # clip latent 10: held on after it
    again = held.place(Cue("wave", at(30), "hi"), 0)  # clip latent 14: it returns one latent later
    assert again.status == "blended" and again.stroke_time == 30 * SECONDS_PER_LATENT
    assert [p.stroke for p in placed(held, "wave")] == [20, 30]


def test_a_flood_of_merged_cues_writes_one_log_line_and_counts_them_all(plan, caplog, monkeypatch):
    """An OSC gesture flood wrote a "merged" line per cue (1,829 in 8 s)."""
    monkeypatch.setattr("gesturecast.log_throttle.time", SimpleNamespace(monotonic=lambda: 0.0))  # one interval
    plan.place(Cue("wave", at(20)), 0)
    with caplog.at_level(logging.INFO):
        outcomes = [plan.place(Cue("wave", at(20)), 0) for _ in range(200)]
    assert {outcome.status for outcome in outcomes} == {"merged"}
    assert len([r for r in caplog.records if "merged" in r.getMessage()]) == 1
    assert plan.summary()["merged"] == 200
