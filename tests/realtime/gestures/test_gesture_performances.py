"""A gesture's performances: recorded takes in turn, tempo and amplitude drawn from the seed, the same seed the same
performances; a stream's performances of the shipped wave play different recordings."""

import numpy as np
import pytest

from gesturecast.realtime.gestures.clips import (
    AMPLITUDE_RANGE,
    PERFORMANCES,
    TEMPO_RANGE,
    ClipMotion,
    performance,
    performances,
    rotation_columns,
)
from gesturecast.realtime.gestures.lexicon import load_lexicon
from gesturecast.realtime.run.engine_setup import performed_motions

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
