"""The waveform voice transforms do what docs/voices.md says they do (measured on synthetic signals)."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.models.dataset import voice_transforms as vt

pytest.importorskip("librosa")
SR = 16000


def harmonic_voice(f0: float, seconds: float = 1.0) -> np.ndarray:
    """A buzz at ``f0`` with 1/k harmonics up to 4 kHz (a crude voiced vowel)."""
    t = np.arange(int(seconds * SR)) / SR
    harmonics = range(1, int(4000 // f0) + 1)
    return (0.1 * sum(np.sin(2 * np.pi * k * f0 * t) / k for k in harmonics)).astype(np.float32)


def median_f0(audio: np.ndarray) -> float:
    import librosa

    return float(np.median(librosa.yin(audio, fmin=60, fmax=500, sr=SR, frame_length=1024)[5:-5]))


def level_db(audio: np.ndarray) -> float:
    return 10 * np.log10(np.mean(audio.astype(np.float64) ** 2))


@pytest.mark.parametrize("semitones", [-4.0, 4.0, 8.0])
def test_pitch_shift_moves_f0_by_the_semitone_ratio(semitones):
    shifted = vt.pitch_shift(harmonic_voice(150.0), SR, semitones)
    assert median_f0(shifted) == pytest.approx(150.0 * 2 ** (semitones / 12), rel=0.02)


def test_formant_shift_keeps_f0_and_moves_the_spectral_centroid():
    voice = harmonic_voice(150.0)
    import librosa

    up = vt.formant_shift(voice, 1.2)
    assert median_f0(up) == pytest.approx(150.0, rel=0.02)
    centroid = [float(np.median(librosa.feature.spectral_centroid(y=x, sr=SR))) for x in (voice, up)]
    assert centroid[1] > centroid[0] * 1.1


def test_gain_is_exactly_minus_20_db():
    voice = harmonic_voice(200.0)
    assert level_db(vt.apply_gain(voice, -20.0)) - level_db(voice) == pytest.approx(-20.0, abs=1e-3)


def test_white_noise_is_20_db_below_the_signal():
    voice = harmonic_voice(200.0, 3.0)
    noise = vt.add_white_noise(voice, 20.0, np.random.default_rng(0)) - voice
    assert level_db(voice) - level_db(noise) == pytest.approx(20.0, abs=0.2)


@pytest.mark.parametrize(("hz", "lowest", "highest"), [(100.0, None, -20.0), (1000.0, -1.0, 1.0),
                                                       (6000.0, None, -20.0)])
def test_telephone_band_passes_300_to_3400_hz_only(hz, lowest, highest):
    tone = np.sin(2 * np.pi * hz * np.arange(SR) / SR).astype(np.float32)
    change = level_db(vt.telephone_band(tone, SR)[2000:-2000]) - level_db(tone[2000:-2000])
    assert change <= highest
    if lowest is not None:
        assert change >= lowest


def test_reverb_keeps_level_and_length_and_smears_a_click():
    click = np.zeros(SR, np.float32)
    click[1000] = 1.0
    wet = vt.reverb(click, SR, np.random.default_rng(0))
    assert wet.shape == click.shape
    assert level_db(wet) == pytest.approx(level_db(click), abs=1e-3)
    assert np.abs(wet[1000 + int(0.1 * SR):]).max() > 0  # a tail 100 ms after the click


def test_random_voice_keeps_length_and_is_seeded():
    voice = harmonic_voice(180.0)
    first = vt.random_voice(voice, SR, np.random.default_rng(3))
    assert first.shape == voice.shape
    np.testing.assert_array_equal(first, vt.random_voice(voice, SR, np.random.default_rng(3)))
