"""A gesture's performances: tempo and amplitude drawn from the seed, the same seed the same performances."""

import numpy as np

from gesturecast.realtime.gestures.clips import (
    AMPLITUDE_RANGE,
    PERFORMANCES,
    TEMPO_RANGE,
    ClipMotion,
    performance,
    performances,
    rotation_columns,
)

D = 136


def clip() -> ClipMotion:
    t = np.linspace(0.0, 1.0, 60)[:, None]  # (T, 1)
    features = np.tile(np.sin(np.pi * t), (1, D)).astype(np.float32)  # (T, D) rises and falls back
    return ClipMotion("wave", features, 30, ("arms",))


def test_a_faster_larger_performance_is_shorter_its_stroke_moved_with_it_and_its_arms_turn_further():
    played = performance(clip(), tempo=1.2, amplitude=1.1)
    assert played.features.shape[0] == 50 and played.stroke_frame == 25
    arms = rotation_columns(("arms",), D)
    assert np.allclose(played.features[25, arms], 1.1 * clip().features[30, arms], atol=0.02)
    assert np.allclose(played.features[25, ~arms], clip().features[30, ~arms], atol=0.02)  # other columns as recorded


def test_performances_are_drawn_from_the_seed():
    first, again, other = performances(clip(), 0), performances(clip(), 0), performances(clip(), 1)
    assert len(first) == PERFORMANCES
    assert all(np.array_equal(a.features, b.features) for a, b in zip(first, again, strict=True))
    assert any(a.features.shape != b.features.shape or not np.allclose(a.features, b.features)
               for a, b in zip(first, other, strict=True))
    lengths = [p.features.shape[0] for p in first]
    assert all(60 / TEMPO_RANGE[1] - 1 <= n <= 60 / TEMPO_RANGE[0] + 1 for n in lengths)
    peak = clip().features[:, rotation_columns(("arms",), D)].max()
    assert all(AMPLITUDE_RANGE[0] * peak - 0.02 <= p.features.max() <= AMPLITUDE_RANGE[1] * peak + 0.02
               for p in first)
