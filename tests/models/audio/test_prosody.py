"""The prosody front end: streaming = offline for any chunking, pitch and voicing right, voice level and
pitch normalised away, and old configs keep their log-mel front end."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.prosody import PitchTracker, padded_spectrum
from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor, extract_features

PROSODY = FeatureConfig(kind="prosody")


def buzz(f0: float, seconds: float, amplitude: float = 0.1) -> np.ndarray:
    """A harmonic voice at ``f0`` in 0.35 s syllables separated by 0.15 s of silence."""
    t = np.arange(int(seconds * SAMPLE_RATE)) / SAMPLE_RATE
    tone = sum(np.sin(2 * np.pi * k * f0 * t) / k for k in range(1, int(4000 // f0) + 1))
    return (amplitude * ((t % 0.5) < 0.35) * tone).astype(np.float32)


@pytest.fixture(scope="module")
def speech(shared_data):
    return load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: 6 * SAMPLE_RATE]


@pytest.mark.parametrize("chunk", [1, 160, 533, 4097])
def test_streaming_equals_offline_for_every_chunk_size(speech, chunk):
    offline = extract_features(speech, PROSODY)
    extractor = StreamingFeatureExtractor(PROSODY)
    streamed = np.concatenate([extractor.push(speech[i : i + chunk]) for i in range(0, len(speech), chunk)])
    np.testing.assert_array_equal(streamed, offline)
    assert offline.shape[1] == PROSODY.num_features == 10


def test_pitch_tracker_finds_f0_and_voicing():
    taper = np.hanning(1025)[:-1]
    tracker = PitchTracker(SAMPLE_RATE, taper, 3.0, 30)
    voiced = buzz(180.0, 0.5)[None, :1024]
    noise = np.random.default_rng(0).standard_normal((1, 1024)) * 0.1
    f0, voicing = tracker.f0_and_voicing(padded_spectrum(np.concatenate([voiced, noise]), taper))
    assert f0[0] == pytest.approx(180.0, rel=0.01)
    assert voicing[0] > 0.9 > 0.5 > voicing[1]


def test_level_and_pitch_of_the_voice_are_normalised_away():
    """A voice 20 dB quieter gives the same bands and energy, one 4 semitones lower the same relative pitch,
    within 2 dB and 0.5 st once the running means adapted (10 s of speech, time constant 3 s; unnormalised, the
    levels would differ by 20 dB and the pitch by 4 st)."""
    layout = PROSODY.layout
    loud = extract_features(buzz(150.0, 12.0), PROSODY)[-60:]
    quiet = extract_features(buzz(150.0, 12.0, 0.01), PROSODY)[-60:]
    low = extract_features(buzz(150.0 * 2 ** (-4 / 12), 12.0), PROSODY)[-60:]
    pitch = layout["pitch"].start
    voiced = (low[:, pitch] != 0) & (loud[:, pitch] != 0) & (quiet[:, pitch] != 0)
    for name in ("bands", "energy"):  # in speech; silence stays absolute (−100 dB minus the voice's mean)
        np.testing.assert_allclose(quiet[voiced, layout[name]], loud[voiced, layout[name]], atol=2.0)
    assert voiced.sum() > 30
    np.testing.assert_allclose(low[voiced, pitch], loud[voiced, pitch], atol=0.5)
    assert np.median(loud[voiced, layout["voicing"].start]) > 0.9


def test_configs_saved_without_a_kind_keep_the_mel_front_end():
    stored = FeatureConfig().to_dict()
    stored.pop("kind")
    assert FeatureConfig.from_dict(stored).kind == "mel"
    assert FeatureConfig.from_dict(PROSODY.to_dict()) == PROSODY
    with pytest.raises(ValueError, match="unknown feature front end"):
        FeatureConfig(kind="wavlm")
