"""Voice and channel augmentation of the paired takes' audio features for denoiser training.

Only two speakers have paired speech + motion, so a denoiser can learn their timbre, level and
room instead of the speech rhythm. Each training window of a paired take gets a random "new
voice and channel", applied in the dB domain of the runtime features so that it is what the same
feature code would compute from such audio (:mod:`gesturecast.models.audio.streaming`):

- gain g dB: log-mel and frame energy both shift by g (a waveform gain, exactly, above the floor);
- spectral tilt and smooth EQ: a per-band dB curve added to the log-mel (a linear filter whose
  response is smooth across a band, exactly); the energy moves by the curve's mean (approximate);
- formant / pitch shift: the log-mel resampled along the band axis by s bands (vocal-tract-length
  perturbation, Jaitly & Hinton 2013; a frequency scaling is close to a band shift on the mel scale);
- additive stationary noise at a random level: power addition per band, 10·log10(10^(x/10) + 10^(n/10));
- band masking (SpecAugment, Park et al. 2019): a random run of bands set to the training mean.

Onset strength (spectral flux) is recomputed from the augmented log-mel with the runtime formula;
the first frame of a window compares with itself (flux 0). The speaking flag is kept. Frames stay
floored at the features' −100 dB.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.audio.dsp import DB_PER_POWER_DECADE, spectral_flux
from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig

DB_FLOOR = -100.0  # the features' floor (feature_dsp.POWER_FLOOR / RMS_FLOOR)
EQ_COMPONENTS = 3  # random cosines over the band axis


@dataclass(frozen=True)
class AudioAugmentConfig:
    gain_db: tuple[float, float] = (-20.0, 10.0)
    tilt_db: float = 8.0  # ± dB from the lowest to the highest band (linear in band index)
    eq_db: float = 3.0  # amplitude of each smooth EQ cosine
    band_shift: float = 4.0  # ± bands of formant / pitch shift
    noise_probability: float = 0.5
    noise_db: tuple[float, float] = (-75.0, -45.0)  # stationary noise level per band
    mask_probability: float = 0.5
    mask_bands: int = 8  # at most this many adjacent bands masked


def shift_bands(mel_db: np.ndarray, shift: float) -> np.ndarray:
    """(T, M) → (T, M): value of band b taken from band b − shift (linear interpolation, edges held)."""
    bands = np.arange(mel_db.shape[1], dtype=np.float64)
    source = np.clip(bands - shift, 0.0, bands[-1])
    low = np.floor(source).astype(int)
    high = np.minimum(low + 1, len(bands) - 1)
    weight = source - low  # (M,)
    return mel_db[:, low] * (1.0 - weight) + mel_db[:, high] * weight


def add_noise_db(level_db: np.ndarray, noise_db: float) -> np.ndarray:
    """Power sum of a signal in dB and a stationary noise at ``noise_db``."""
    return DB_PER_POWER_DECADE * np.log10(10.0 ** (level_db / DB_PER_POWER_DECADE)
                                          + 10.0 ** (noise_db / DB_PER_POWER_DECADE))


class FeatureAugmenter:
    """Augments normalised feature windows (T, F): denormalise, change voice + channel, renormalise."""

    def __init__(self, config: AudioAugmentConfig, stats: FeatureStats, feature_config: FeatureConfig) -> None:
        self.config = config
        self.stats = stats
        layout = feature_config.layout
        self.mel, self.onset, self.energy = layout["mel"], layout["onset"], layout["energy"]
        self.num_bands = feature_config.n_mels

    def _band_curve(self, rng: np.random.Generator) -> np.ndarray:
        """Tilt + smooth EQ in dB per band (M,)."""
        cfg = self.config
        position = np.linspace(-0.5, 0.5, self.num_bands)  # (M,)
        curve = rng.uniform(-cfg.tilt_db, cfg.tilt_db) * position
        for component in range(1, EQ_COMPONENTS + 1):
            phase = rng.uniform(0.0, 2.0 * np.pi)
            curve += rng.uniform(-cfg.eq_db, cfg.eq_db) * np.cos(np.pi * component * (position + 0.5) + phase)
        return curve

    def __call__(self, window: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        cfg = self.config
        raw = self.stats.invert(window).astype(np.float64)  # (T, F) dB features
        mel = shift_bands(raw[:, self.mel], rng.uniform(-cfg.band_shift, cfg.band_shift))  # (T, M)
        gain = rng.uniform(*cfg.gain_db)
        curve = self._band_curve(rng)  # (M,)
        mel = np.maximum(mel + gain + curve, DB_FLOOR)
        energy = np.maximum(raw[:, self.energy] + gain + curve.mean(), DB_FLOOR)  # (T, 1)
        if rng.random() < cfg.noise_probability:
            noise = rng.uniform(*cfg.noise_db)
            mel, energy = add_noise_db(mel, noise), add_noise_db(energy, noise)
        raw[:, self.mel] = mel
        raw[:, self.energy] = energy
        raw[:, self.onset] = spectral_flux(mel, mel[0])[:, None]
        augmented = self.stats.apply(raw.astype(np.float32))  # (T, F)
        if rng.random() < cfg.mask_probability:
            width = int(rng.integers(1, cfg.mask_bands + 1))
            first = self.mel.start + int(rng.integers(0, self.num_bands - width + 1))
            augmented[:, first : first + width] = 0.0  # the training mean
        return augmented
