import numpy as np

from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig


def test_fit_over_takes_normalises_and_round_trips():
    config = FeatureConfig()
    rng = np.random.default_rng(0)
    takes = [rng.normal(3.0, 2.0, (n, config.num_features)).astype(np.float32) for n in (100, 250)]
    flag = config.layout["speaking"]
    for take in takes:
        take[:, flag] = rng.integers(0, 2, (take.shape[0], 1))
    stats = FeatureStats.fit(takes, config)
    normalised = stats.apply(np.concatenate(takes))
    np.testing.assert_allclose(np.delete(normalised, flag.start, axis=1).mean(axis=0), 0.0, atol=1e-4)
    np.testing.assert_allclose(np.delete(normalised, flag.start, axis=1).std(axis=0), 1.0, atol=1e-3)
    np.testing.assert_array_equal(normalised[:, flag], np.concatenate(takes)[:, flag])
    restored = FeatureStats.from_dict(stats.to_dict())
    np.testing.assert_array_equal(restored.apply(takes[0]), stats.apply(takes[0]))
    np.testing.assert_allclose(stats.invert(stats.apply(takes[0])), takes[0], atol=1e-5)
