"""Voice / channel augmentation: a gain equals the features of the louder audio; shapes, flags and seeds hold."""

import numpy as np
import pytest

from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig, extract_features
from gesturecast.models.training.audio_augment import AudioAugmentConfig, FeatureAugmenter, add_noise_db, shift_bands

RATE = 16000
CONFIG = FeatureConfig()
NOTHING = AudioAugmentConfig(gain_db=(0.0, 0.0), tilt_db=0.0, eq_db=0.0, band_shift=0.0, noise_probability=0.0,
                             mask_probability=0.0)


def modulated_noise(seconds: float = 3.0) -> np.ndarray:
    rng = np.random.default_rng(0)
    t = np.arange(int(seconds * RATE)) / RATE
    return ((0.05 + 0.2 * (1 + np.sin(2 * np.pi * 2.0 * t))) * rng.standard_normal(len(t))).astype(np.float32)


@pytest.fixture(scope="module")
def speech_and_stats():
    audio = modulated_noise()
    features = extract_features(audio, CONFIG)
    return audio, features, FeatureStats.fit([features], CONFIG)


def test_gain_matches_the_features_of_the_scaled_audio(speech_and_stats):
    audio, features, stats = speech_and_stats
    gain_db = -12.0
    augmenter = FeatureAugmenter(AudioAugmentConfig(**{**vars(NOTHING), "gain_db": (gain_db, gain_db)}), stats, CONFIG)
    augmented = stats.invert(augmenter(stats.apply(features), np.random.default_rng(0)))
    expected = extract_features(audio * np.float32(10 ** (gain_db / 20)), CONFIG)
    layout = CONFIG.layout
    for name in ("mel", "energy", "onset"):
        assert augmented[:, layout[name]] == pytest.approx(expected[:, layout[name]], abs=2e-3), name


def test_nothing_changes_without_augmentation(speech_and_stats):
    _, features, stats = speech_and_stats
    window = stats.apply(features)
    assert FeatureAugmenter(NOTHING, stats, CONFIG)(window, np.random.default_rng(0)) == pytest.approx(window, abs=1e-4)


def test_default_augmentation_keeps_shape_and_speaking_flag_and_is_seeded(speech_and_stats):
    _, features, stats = speech_and_stats
    window = stats.apply(features)
    augmenter = FeatureAugmenter(AudioAugmentConfig(), stats, CONFIG)
    first = augmenter(window, np.random.default_rng(5))
    assert first.shape == window.shape and first.dtype == np.float32
    speaking = CONFIG.layout["speaking"]
    assert np.array_equal(first[:, speaking], window[:, speaking])
    assert np.array_equal(first, augmenter(window, np.random.default_rng(5)))
    assert not np.allclose(first, augmenter(window, np.random.default_rng(6)))


def test_band_shift_moves_columns_and_holds_edges():
    mel = np.tile(np.arange(8.0), (2, 1))  # (T, M) band index as value
    shifted = shift_bands(mel, 2.0)
    assert shifted[0] == pytest.approx([0, 0, 0, 1, 2, 3, 4, 5])
    assert shift_bands(mel, 0.5)[0, 3] == pytest.approx(2.5)


def test_noise_adds_power():
    assert add_noise_db(np.array([-60.0]), -60.0) == pytest.approx(-60.0 + 10 * np.log10(2))
    assert add_noise_db(np.array([-20.0]), -80.0) == pytest.approx(-20.0, abs=1e-4)


def test_batch_sampler_augments_only_paired_audio():
    from denoiser_helpers import TINY

    from gesturecast.models.training.denoiser_trainer import LatentBatchSampler, LatentClip

    frames = 12 * TINY.frames_per_latent + TINY.audio_lookahead
    paired = LatentClip(np.zeros((12, TINY.latent_dim), np.float32), np.zeros((frames, TINY.audio_dim), np.float32),
                        np.zeros(TINY.style_dim, np.float32))
    silent = LatentClip(np.zeros((12, TINY.latent_dim), np.float32), None, np.zeros(TINY.style_dim, np.float32))
    sampler = LatentBatchSampler([paired, silent], TINY, 4, 0.5, np.random.default_rng(0),
                                 augmenter=lambda window, rng: window + 1.0)
    _, audio, mask, _, _ = sampler.sample(16)
    assert 0 < mask.sum() < 16
    assert bool((audio[mask == 1] == 1.0).all()) and bool((audio[mask == 0] == 0.0).all())
