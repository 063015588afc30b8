"""A cue plan keeps what it holds bounded (a count, and a horizon for live words) and looks only at the clips that
can overlap a cue or a latent, whatever order the cues came in."""

import numpy as np
import pytest

from gesturecast.realtime.gestures.cues import MAX_AHEAD_S, Cue, CuePlan, CueRefused, GestureClip

C, D = 8, 10
SECONDS_PER_LATENT = 4 / 30
ARMS = np.arange(C) < 4
TORSO = ~ARMS


def clip(name: str, channels: np.ndarray, length: int) -> GestureClip:
    latents = np.full((length, C), len(name), np.float32)  # (N, C)
    return GestureClip(name, latents, channels, length // 2, np.zeros((length * 4, D), np.float32), np.arange(D) < 3)


def plan(max_placements: int = 1000) -> CuePlan:
    clips = {"wave": clip("wave", ARMS, 10), "bow": clip("bow", ARMS | TORSO, 30), "nod": clip("nod", TORSO, 6)}
    return CuePlan(clips, SECONDS_PER_LATENT, max_placements=max_placements)


def test_cues_placed_out_of_order_overlap_and_cover_as_when_placed_in_order():
    shuffled, ordered = plan(), plan()
    cues = [Cue("wave", 40.0), Cue("nod", 10.0), Cue("bow", 30.0), Cue("wave", 10.2), Cue("bow", 20.0),
            Cue("nod", 40.5), Cue("wave", 29.0)]
    placed = [shuffled.place(cue, 0).stroke_time is not None for cue in cues]
    assert placed == [True, True, True, True, True, True, False]  # the last wave overlaps the bow at 30 s (arms)
    for cue, kept in sorted(zip(cues, placed, strict=True), key=lambda pair: pair[0].time):
        if kept:
            ordered.place(cue, 0)
    assert [p.first for p in shuffled.placements] == sorted(p.first for p in ordered.placements)
    for latent in range(0, 400):
        mine, theirs = shuffled.imposition(latent), ordered.imposition(latent)
        assert (mine is None) == (theirs is None) and (mine is None or sorted(mine.names.split("+")) ==
                                                       sorted(theirs.names.split("+")))
    shuffled.forget_before(250)
    assert [p.cue.time for p in shuffled.placements] == [40.0, 40.5]  # the ones not over by latent 250


def test_a_full_plan_refuses_further_cues_with_one_line():
    small = plan(max_placements=3)
    for time in (5.0, 10.0, 15.0):
        assert small.place(Cue("wave", time), 0).status == "on time"
    with pytest.raises(CueRefused, match="already holds 3 gestures to come"):
        small.place(Cue("wave", 20.0), 0)
    small.forget_before(1000)
    assert small.place(Cue("wave", 200.0), 0).status == "on time"  # room again once they have played


def test_live_cue_times_far_ahead_of_the_stream_are_refused():
    cues = plan()
    cues.check_ahead([10.0, MAX_AHEAD_S], next_latent=0)
    with pytest.raises(CueRefused, match=r"a word at 1e\+06 s is .* ahead of the stream"):
        cues.check_ahead([1e6], next_latent=0)
    cues.check_ahead([1e6], next_latent=int(1e6 / SECONDS_PER_LATENT))  # not ahead once the stream is there


def test_a_cue_time_that_is_not_a_stream_time_is_refused_in_one_line():
    cues = plan()
    for time in (1e308, float("inf"), float("nan")):
        with pytest.raises(CueRefused, match="not a stream time"):
            cues.place(Cue("wave", time), 0)
