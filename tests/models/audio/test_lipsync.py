"""Viseme weights: synthetic vowels land in their class, silence gives zeros, streaming = offline."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from gesturecast.frames import VISEME_VOWELS
from gesturecast.models.audio.formants import FormantTracker
from gesturecast.models.audio.lipsync import REFERENCE_FORMANTS_HZ, SILENT_MOUTH, LipSyncConfig, mouth_class
from gesturecast.models.audio.streaming import StreamingFeatureExtractor, extract_visemes

SAMPLE_RATE = 16000
BANDWIDTHS_HZ = (80.0, 100.0, 150.0)
THIRD_FORMANT_HZ = 2700.0
LEAD_IN = 4800  # samples
LEAD_IN_FRAMES = 9


def synthetic_vowel(formants_hz: tuple[float, ...], f0: float, seconds: float = 0.6, level: float = 0.3) -> np.ndarray:
    """A glottal pulse train at ``f0`` through a cascade of two-pole resonators (Klatt-style source-filter)."""
    n = int(seconds * SAMPLE_RATE)
    pulses = np.zeros(n)
    pulses[np.arange(0, n, SAMPLE_RATE / f0).astype(int)] = 1.0
    signal = lfilter([1.0], [1.0, -0.95], pulses)  # glottal spectral tilt
    for frequency, bandwidth in zip(formants_hz, BANDWIDTHS_HZ, strict=True):
        radius = np.exp(-np.pi * bandwidth / SAMPLE_RATE)
        angle = 2 * np.pi * frequency / SAMPLE_RATE
        signal = lfilter([1.0 - radius], [1.0, -2 * radius * np.cos(angle), radius**2], signal)
    return (signal / np.abs(signal).max() * level).astype(np.float32)


def vowel_signal(index: int, scale: float, f0: float) -> np.ndarray:
    """0.3 s of silence (the voice-activity detector learns the floor), then the vowel."""
    f1, f2 = REFERENCE_FORMANTS_HZ[index] * scale
    return np.concatenate([np.zeros(LEAD_IN, np.float32), synthetic_vowel((f1, f2, THIRD_FORMANT_HZ * scale), f0)])


@pytest.mark.parametrize("scale, f0", [(1.0, 110.0), (1.17, 210.0)])
@pytest.mark.parametrize("index", range(len(VISEME_VOWELS)))
def test_synthetic_vowels_get_their_class(index: int, scale: float, f0: float) -> None:
    weights = extract_visemes(vowel_signal(index, scale, f0))  # (T, 5)
    steady = weights[LEAD_IN_FRAMES + 5:]  # after the smoothing's attack
    assert (mouth_class(steady) == index).mean() > 0.9


def test_formant_tracker_finds_synthetic_formants() -> None:
    signal = synthetic_vowel((500.0, 1500.0, 2500.0), f0=120.0)
    f1, f2 = FormantTracker().track(signal[None, -2048:])[0]
    assert abs(f1 - 500.0) < 60.0 and abs(f2 - 1500.0) < 100.0


def test_silence_gives_zero_weights() -> None:
    weights = extract_visemes(np.zeros(SAMPLE_RATE, np.float32))
    assert weights.shape == (30, len(VISEME_VOWELS)) and not weights.any()
    assert (mouth_class(weights) == len(VISEME_VOWELS)).all()


def test_weights_lie_in_unit_range_and_sum_to_the_opening() -> None:
    audio = np.concatenate([vowel_signal(0, 1.0, 120.0), np.zeros(8000, np.float32), vowel_signal(1, 1.1, 180.0)])
    weights = extract_visemes(audio)
    assert weights.min() >= 0.0 and weights.sum(axis=1).max() <= 1.0 + 1e-6
    assert weights.sum(axis=1).max() > 0.5  # the vowels open the mouth
    assert weights[-5:].sum(axis=1).min() > SILENT_MOUTH


def test_quieter_speech_opens_the_mouth_less() -> None:
    loud = extract_visemes(vowel_signal(0, 1.0, 120.0))[LEAD_IN_FRAMES + 5:].sum(axis=1).mean()
    quiet = extract_visemes(vowel_signal(0, 1.0, 120.0) * 0.1)[LEAD_IN_FRAMES + 5:].sum(axis=1).mean()
    assert quiet < loud


@pytest.mark.parametrize("chunk", [1, 160, 533, 4096])
def test_streaming_equals_offline_for_any_chunk_size(chunk: int) -> None:
    rng = np.random.default_rng(0)
    audio = np.concatenate([vowel_signal(2, 1.0, 130.0), 0.01 * rng.normal(size=4000).astype(np.float32),
                            vowel_signal(3, 1.2, 220.0)])
    offline = extract_visemes(audio)
    extractor = StreamingFeatureExtractor(lipsync=LipSyncConfig())
    blocks = []
    for start in range(0, len(audio), chunk):
        extractor.push(audio[start:start + chunk])
        blocks.append(extractor.take_visemes())
    np.testing.assert_array_equal(np.concatenate(blocks), offline)


def test_features_without_lipsync_refuse_to_hand_out_visemes() -> None:
    with pytest.raises(ValueError, match="without lipsync"):
        StreamingFeatureExtractor().take_visemes()
