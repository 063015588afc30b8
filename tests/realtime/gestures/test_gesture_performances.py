"""A gesture's performances: recorded takes in turn, tempo and amplitude drawn from the seed, the same seed the same
performances; a stream's performances of the shipped wave play different recordings; consecutive ones change hand
(gestures that name none and are not symmetric) and size."""

import numpy as np
import pytest

from gesturecast.models.motion.motion_features import features_to_motion
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.realtime.gestures.clips import (
    AMPLITUDE_RANGE,
    PERFORMANCES,
    TEMPO_RANGE,
    ClipMotion,
    mirrorable,
    mirrored,
    performance,
    performances,
    played_larger,
    rotation_columns,
    symmetric,
)
from gesturecast.realtime.gestures.lexicon import load_lexicon
from gesturecast.realtime.gestures.repertoire import performed_motions
from gesturecast.realtime.gestures.strokes import body_frame_positions, release_frame

D = 136


def clip(source: str = "take-a", frames: int = 60) -> ClipMotion:
    t = np.linspace(0.0, 1.0, frames)[:, None]  # (T, 1)
    features = np.tile(np.sin(np.pi * t), (1, D)).astype(np.float32)  # (T, D) rises and falls back
    return ClipMotion("wave", features, frames // 2, ("arms",), source)


def test_a_faster_larger_performance_is_shorter_its_stroke_moved_with_it_and_its_arms_turn_further():
    played = performance(clip(), tempo=1.2, amplitude=1.1)
    assert played.features.shape[0] == 50 and played.stroke_frame == 25 and played.source == "take-a"
    arms = rotation_columns(("arms",), D)
    assert np.allclose(played.features[25, arms], 1.1 * clip().features[30, arms], atol=0.02)
    assert np.allclose(played.features[25, ~arms], clip().features[30, ~arms], atol=0.02)  # other columns as recorded


def test_performances_are_drawn_from_the_seed():
    first, again, other = performances([clip()], 0), performances([clip()], 0), performances([clip()], 1)
    assert len(first) == PERFORMANCES
    assert all(np.array_equal(a.features, b.features) for a, b in zip(first, again, strict=True))
    assert any(a.features.shape != b.features.shape or not np.allclose(a.features, b.features)
               for a, b in zip(first, other, strict=True))
    lengths = [p.features.shape[0] for p in first]
    assert all(60 / TEMPO_RANGE[1] - 1 <= n <= 60 / TEMPO_RANGE[0] + 1 for n in lengths)
    peak = clip().features[:, rotation_columns(("arms",), D)].max()
    assert all(AMPLITUDE_RANGE[0] * peak - 0.02 <= p.features.max() <= AMPLITUDE_RANGE[1] * peak + 0.02
               for p in first)


def test_performances_play_the_takes_in_turn_in_an_order_drawn_from_the_seed():
    takes = [clip("take-a", 60), clip("take-b", 72), clip("take-c", 48)]
    orders = {seed: [p.source for p in performances(takes, seed)] for seed in range(8)}
    for order in orders.values():
        assert len(order) == 6 and set(order[:3]) == {"take-a", "take-b", "take-c"} and order[3:] == order[:3]
        assert all(a != b for a, b in zip(order, order[1:] + order[:1], strict=True))  # played again from the first
    assert len({tuple(order) for order in orders.values()}) > 1  # another seed, another order
    with pytest.raises(ValueError, match="at least one take"):
        performances([], 0)


def test_a_stream_plays_different_recorded_waves_and_one_take_gestures_still_vary():
    motions = performed_motions(load_lexicon(), None, seed=0)
    waves = [m.source for m in motions if m.name == "wave"]
    assert len(waves) == 6 and len(set(waves)) == 3
    assert all(a != b for a, b in zip(waves, waves[1:], strict=False))
    assert all(source.startswith("dataset-2_wave-both-hands_normal_") for source in waves)
    cheers = {m.source for m in motions if m.name == "raise-both"}
    assert len(cheers) == 3 and all("_active_" in source for source in cheers)  # the take that means a cheer
    bows = [m for m in motions if m.name == "bow"]
    assert {m.source for m in bows} == {"dataset-1_bow_normal_001"}  # the data has one neutral bow
    assert len({(m.features.shape[0], float(np.abs(m.features).sum())) for m in bows}) == PERFORMANCES
    old = performed_motions(load_lexicon(), "elderly", seed=0)
    assert all("_elderly_" in m.source for m in old if m.name == "wave")


def wrist_heights(motion: ClipMotion) -> np.ndarray:
    """(T, 2) the left and right wrists' heights above their shoulders (body frame, m)."""
    body = body_frame_positions(features_to_motion(motion.features))  # (T, J, 3)
    joint = CANONICAL.index
    return np.stack([body[:, joint(f"{side}Hand"), 1] - body[:, joint(f"{side}UpperArm"), 1]
                     for side in ("Left", "Right")], axis=1)


def shipped_take(name: str) -> ClipMotion:
    entry = next(entry for entry in load_lexicon() if entry.name == name)
    take = entry.takes("neutral")[0]
    return ClipMotion(name, np.asarray(take.features, np.float32), take.stroke_frame, entry.parts, take.source)


def test_a_mirrored_performance_waves_the_other_hand_and_mirroring_twice_gives_it_back():
    wave = shipped_take("wave-right")
    other = mirrored(wave)
    heights, swapped = wrist_heights(wave), wrist_heights(other)
    assert heights[wave.stroke_frame, 1] > 0.2 > heights[wave.stroke_frame, 0]  # the right hand up
    assert np.allclose(swapped[:, ::-1], heights, atol=1e-3) and other.stroke_frame == wave.stroke_frame
    assert np.allclose(mirrored(other).features[:, 4:], wave.features[:, 4:], atol=2e-3)  # float16 takes


def test_consecutive_performances_change_hand_every_time_and_size_in_turns_of_two():
    played = performances([shipped_take("hand-up")], seed=3, mirror=True)
    hands = [int(np.argmax(wrist_heights(p)[p.stroke_frame])) for p in played]  # 0: left hand up, 1: right
    assert all(a != b for a, b in zip(hands, hands[1:] + hands[:1], strict=True))
    assert [played_larger(k, hands_alternate=True) for k in range(4)] == [0, 1, 1, 0]


def test_a_symmetric_gesture_leads_with_either_hand_in_turns_and_changes_size_every_time_the_larger_slower():
    raise_both = shipped_take("raise-both")
    assert symmetric(raise_both) and symmetric(shipped_take("wave")) and not symmetric(shipped_take("bow"))
    for seed in range(4):  # never mirrored: the hands lead in turns, the other arm lower
        played = performances([raise_both], seed, mirror=True)
        leads = [int(np.argmax(wrist_heights(p)[p.stroke_frame])) for p in played]
        assert all(a != b for a, b in zip(leads, leads[1:] + leads[:1], strict=True))
    assert [played_larger(k, hands_alternate=False) for k in range(4)] == [0, 1, 0, 1]
    arms = rotation_columns(("arms",), D)
    low, high = AMPLITUDE_RANGE
    for seed in range(4):
        sizes = [float(p.features[:, arms].max()) for p in performances([clip()], seed)]  # the sine's peak: amplitude
        assert all(size > (2 * high + low) / 3 - 0.01 or size < (high + 2 * low) / 3 + 0.01 for size in sizes)
        larger = [size > (2 * high + low) / 3 - 0.01 for size in sizes]
        assert larger in ([False, True] * 2, [True, False] * 2)
        lengths = [p.features.shape[0] for p in performances([clip()], seed)]  # 60 frames recorded
        assert all(n >= 60 if big else n <= 60 for n, big in zip(lengths, larger, strict=True))  # larger is slower


def test_with_two_takes_each_is_played_with_both_hands():
    takes = [shipped_take("hand-up"), mirrored(shipped_take("hand-up"))]  # a right-handed and a left-handed take
    played = performances(takes, seed=0, mirror=True)
    hands = [int(np.argmax(wrist_heights(p)[p.stroke_frame])) for p in played]
    assert len(played) == 4 and sorted(hands) == [0, 0, 1, 1]


def test_a_stream_mirrors_every_other_performance_of_a_gesture_that_names_no_hand_and_never_one_that_does():
    motions = performed_motions(load_lexicon(), None, seed=0, mirror=True)
    hands = {name: [int(np.argmax(wrist_heights(m)[m.stroke_frame])) for m in motions if m.name == name]
             for name in ("wave-right", "hand-up")}
    assert set(hands["wave-right"]) == {1} and len(set(hands["hand-up"])) == 2
    assert mirrorable("hand-up") and mirrorable("guide")
    assert not mirrorable("wave-right") and not mirrorable("raise-left")


def test_a_wave_holds_until_its_release_and_only_returns_after_it():
    wave = shipped_take("wave")
    heights = wrist_heights(wave).max(axis=1)  # (T,) the higher wrist above its shoulder
    release = release_frame(body_frame_positions(features_to_motion(wave.features)))
    assert wave.stroke_frame < release < len(heights) - 10
    assert heights[wave.stroke_frame: release - 5].min() > 0.2 and heights[release] > 0.1  # held up, waving
    assert np.all(np.diff(heights[release + 5:]) < 0.02) and heights[-1] < -0.3  # on its way down, then at rest
