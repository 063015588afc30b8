import numpy as np
import pytest

from gesturecast.models.audio.speaker_norm import PRIOR_LEVEL_DB, SpeakerNormalizer, SpeakerNormConfig
from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor

SAMPLE_RATE = 16000
FPS = 30
GAIN_DB = 20.0
NORMALISED = FeatureConfig(speaker_norm=SpeakerNormConfig(enabled=True))


def syllables(seconds: float, seed: int = 0) -> np.ndarray:
    """Noise bursts at a syllable rate (4 Hz, 60 % duty) with slow level changes over a room-noise floor."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * SAMPLE_RATE)) / SAMPLE_RATE
    envelope = np.maximum(((t * 4) % 1 < 0.6) * (0.5 + 0.4 * np.sin(2 * np.pi * 0.3 * t)), 0.01)
    return (0.05 * envelope * rng.standard_normal(t.size)).astype(np.float32)


def levels(features: np.ndarray, config: FeatureConfig) -> np.ndarray:
    layout = config.layout
    return np.concatenate([features[:, layout["mel"]], features[:, layout["energy"]]], axis=1)  # (T, M + 1)


def test_a_louder_voice_gives_the_same_features_once_the_mean_has_adapted():
    audio = syllables(14.0)
    louder = audio * np.float32(10 ** (GAIN_DB / 20))
    raw_difference = levels(StreamingFeatureExtractor().push(louder), FeatureConfig()) - levels(
        StreamingFeatureExtractor().push(audio), FeatureConfig())
    speaking = StreamingFeatureExtractor().push(audio)[:, FeatureConfig().layout["speaking"]][:, 0] > 0.5
    np.testing.assert_allclose(np.median(raw_difference[speaking], axis=0), GAIN_DB, atol=0.5)
    difference = levels(StreamingFeatureExtractor(NORMALISED).push(louder), NORMALISED) - levels(
        StreamingFeatureExtractor(NORMALISED).push(audio), NORMALISED)
    late = slice(-3 * FPS, None)  # the last 3 s, after ≈ 7 s of speech
    assert np.abs(difference[late][speaking[late]]).max() < 0.15 * GAIN_DB
    assert np.abs(difference[late][speaking[late]]).mean() < np.abs(difference[:FPS][speaking[:FPS]]).mean()


@pytest.mark.parametrize("warm_start", [False, True])
def test_normalised_features_do_not_depend_on_the_chunk_size(warm_start):
    config = FeatureConfig(speaker_norm=SpeakerNormConfig(enabled=True, warm_start=warm_start))
    audio = syllables(4.0, seed=1)
    whole = StreamingFeatureExtractor(config).push(audio)
    extractor = StreamingFeatureExtractor(config)
    chunked = np.concatenate([extractor.push(audio[i : i + 333]) for i in range(0, audio.size, 333)])
    np.testing.assert_array_equal(chunked, whole)


def test_the_mean_moves_on_speech_frames_only():
    normalizer = SpeakerNormalizer(2, SpeakerNormConfig(enabled=True, time_constant_s=1.0), FPS)
    values = np.array([[-20.0, -30.0], [-20.0, -30.0], [-90.0, -90.0]])
    out = normalizer.update(values, np.array([False, True, False]))
    np.testing.assert_allclose(out[0], values[0] - PRIOR_LEVEL_DB)  # before speech: the prior
    moved = PRIOR_LEVEL_DB + (values[1] - PRIOR_LEVEL_DB) / FPS
    np.testing.assert_allclose(out[1], values[1] - moved)
    np.testing.assert_allclose(out[2], values[2] - moved)  # silence does not pull the mean down
    normalizer.reset()
    np.testing.assert_allclose(normalizer.mean, PRIOR_LEVEL_DB)


def test_configs_saved_before_speaker_normalisation_load_with_it_off():
    saved = FeatureConfig().to_dict()
    del saved["speaker_norm"]
    assert FeatureConfig.from_dict(saved).speaker_norm.enabled is False
    assert FeatureConfig.from_dict(NORMALISED.to_dict()) == NORMALISED
    with pytest.raises(ValueError, match="time_constant_s"):
        SpeakerNormConfig(enabled=True, time_constant_s=0.0)


def test_a_warm_start_averages_the_speech_heard_until_one_time_constant():
    normalizer = SpeakerNormalizer(1, SpeakerNormConfig(enabled=True, time_constant_s=1.0, warm_start=True), FPS)
    speech = np.linspace(-30.0, -20.0, 2 * FPS)[:, None]  # (60, 1): two time constants of speech
    out = normalizer.update(speech, np.ones(2 * FPS, bool))
    assert out[0, 0] == 0.0  # the first speech frame is its own mean: no pull from the prior
    np.testing.assert_allclose(speech[:FPS, 0] - out[:FPS, 0], np.cumsum(speech[:FPS, 0]) / np.arange(1, FPS + 1))
    mean = speech[:FPS, 0].mean()
    for value in speech[FPS:, 0]:  # then the usual EMA with weight 1 / (τ fps)
        mean += (value - mean) / FPS
    np.testing.assert_allclose(normalizer.mean, [mean])
    normalizer.reset()
    assert normalizer.speech_frames == 0


def test_bundles_without_a_warm_start_keep_the_prior():
    saved = NORMALISED.to_dict()
    del saved["speaker_norm"]["warm_start"]
    assert FeatureConfig.from_dict(saved).speaker_norm.warm_start is False
