"""The speaker-invariant "prosody" front end: band envelopes, relative pitch and voicing per motion frame.

GestureDiffuCLIP (Ao et al. 2023, Sec. 4.1) conditions on "the beat and volume of speech": onset
strength and amplitude envelopes, which no voice identity survives. This channel computes, from the
same 64 ms Hann window that ends at each frame's end as the log-mel (:mod:`.streaming`):

- ``bands`` (5): power in 80-300, 300-800, 800-1800, 1800-3500 and 3500-8000 Hz, in dB relative to full
  scale (P_band = 2 Σ_band |X_k|² / (N Σ w²), Parseval), and ``energy`` (the frame's RMS dB); these six dB
  values are speaker-normalised: the causal running mean over *voiced* frames (speaking flag on and voicing
  above 0.5, so the pauses the speaking flag bridges do not pull it towards silence) is subtracted
  (:class:`~gesturecast.models.audio.speaker_norm.SpeakerNormalizer`, always on for this front end),
  so a gain, an EQ or another voice's spectral balance fades out within a few seconds of speech;
- ``pitch`` (1): relative pitch in semitones: 12·log2(f0) minus its running mean over voiced frames
  (same time constant), 0 where unvoiced, clipped to ±12; f0 from the normalised autocorrelation of the
  tapered window divided by the taper's own autocorrelation (Boersma 1993), the first peak within 90 % of
  the highest for 60-400 Hz (:func:`first_peak`), refined by parabolic interpolation; a pitch shift of
  the whole voice leaves it unchanged once the mean adapted;
- ``voicing`` (1): that autocorrelation peak's height in [0, 1] (periodicity; 0 in silence).
Onset strength and the speaking flag are the streaming extractor's. Every quantity is per frame or a
frame-by-frame recurrence, so the channel is chunk-size invariant like the rest of the features.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.audio.dsp import DB_PER_POWER_DECADE, POWER_FLOOR
from gesturecast.models.audio.speaker_norm import SpeakerNormalizer, SpeakerNormConfig

BAND_EDGES_HZ = (80.0, 300.0, 800.0, 1800.0, 3500.0, 8000.0)
NUM_BANDS = len(BAND_EDGES_HZ) - 1
PITCH_RANGE_HZ = (60.0, 400.0)
OCTAVE_TOLERANCE = 0.9
VOICED_THRESHOLD = 0.5  # autocorrelation peak above which a speaking frame counts as voiced
PRIOR_PITCH_ST = 7.0  # 12·log2(150 Hz / 100 Hz): the running mean before the first voiced frame
PITCH_REFERENCE_HZ = 100.0
PITCH_CLIP_ST = 12.0
SEMITONES_PER_OCTAVE = 12.0
SILENCE_POWER = 1e-12  # a window whose zero-lag autocorrelation is below this is silent (voicing 0)


def band_bins(sample_rate: int, n_fft: int) -> list[slice]:
    """FFT-bin ranges of the bands (each at least one bin)."""
    hz_per_bin = sample_rate / n_fft
    edges = [int(round(hz / hz_per_bin)) for hz in BAND_EDGES_HZ]
    return [slice(a, max(b, a + 1)) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def band_levels_db(power: np.ndarray, bins: list[slice], taper: np.ndarray) -> np.ndarray:
    """(T, K) |X|² of tapered windows → (T, B) band power in dBFS (module docstring)."""
    scale = 2.0 / (taper.shape[0] * np.sum(taper**2))
    levels = np.stack([power[:, part].sum(axis=1) * scale for part in bins], axis=1)  # (T, B)
    return DB_PER_POWER_DECADE * np.log10(np.maximum(levels, POWER_FLOOR))


def padded_spectrum(windows: np.ndarray, taper: np.ndarray) -> np.ndarray:
    """(T, N) → (T, N + 1) FFT of the tapered windows zero-padded to 2N: its even bins are the N-point FFT
    (the power spectrum of the log-mel and the bands), all of it gives the linear autocorrelation."""
    return np.fft.rfft(windows.astype(np.float64) * taper, n=2 * windows.shape[1], axis=-1)


def autocorrelation(spectrum: np.ndarray, length: int) -> np.ndarray:
    """(T, N + 1) zero-padded spectrum → (T, length) autocorrelation at lags 0 … length − 1."""
    return np.fft.irfft(spectrum.real**2 + spectrum.imag**2, axis=-1)[:, :length]


def first_peak(values: np.ndarray) -> np.ndarray:
    """(T, L) → (T,) index of the first local maximum reaching OCTAVE_TOLERANCE of the row's maximum.

    A periodic signal correlates as well at two and three periods as at one; taking the shortest lag
    whose peak is nearly the highest avoids octave-down errors (as YIN's absolute threshold does)."""
    inner = values[:, 1:-1]  # (T, L - 2)
    peaks = (inner >= values[:, :-2]) & (inner > values[:, 2:])
    peaks &= inner >= OCTAVE_TOLERANCE * values.max(axis=1, keepdims=True)
    return np.where(peaks.any(axis=1), np.argmax(peaks, axis=1) + 1, np.argmax(values, axis=1))


class PitchTracker:
    """Autocorrelation f0 and voicing per window, and the running-mean relative pitch."""

    def __init__(self, sample_rate: int, taper: np.ndarray, time_constant_s: float, fps: float) -> None:
        self.sample_rate = sample_rate
        self.taper = taper
        self.min_lag = int(np.floor(sample_rate / PITCH_RANGE_HZ[1]))
        self.max_lag = int(np.ceil(sample_rate / PITCH_RANGE_HZ[0]))
        taper_ac = autocorrelation(padded_spectrum(np.ones((1, len(taper))), taper), self.max_lag + 2)[0]
        self.taper_ac = taper_ac / taper_ac[0]  # (L,)
        self.rate = 1.0 / (time_constant_s * fps)
        self.reset()

    def reset(self) -> None:
        self.mean_st = PRIOR_PITCH_ST

    def f0_and_voicing(self, spectrum: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(T, N + 1) zero-padded spectra of the tapered windows → f0 Hz (T,), voicing (T,) in [0, 1]."""
        ac = autocorrelation(spectrum, self.max_lag + 2)  # (T, L)
        energy = ac[:, :1]
        normalised = np.where(energy > SILENCE_POWER, ac / np.maximum(energy, SILENCE_POWER), 0.0) / self.taper_ac
        search = normalised[:, self.min_lag : self.max_lag + 1]  # (T, lags)
        peak = first_peak(search) + self.min_lag  # (T,)
        rows = np.arange(len(peak))
        left, centre, right = normalised[rows, peak - 1], normalised[rows, peak], normalised[rows, peak + 1]
        curvature = left - 2.0 * centre + right
        offset = np.where(curvature < 0, 0.5 * (left - right) / np.where(curvature < 0, curvature, -1.0), 0.0)
        return self.sample_rate / (peak + np.clip(offset, -0.5, 0.5)), np.clip(centre, 0.0, 1.0)

    def relative_pitch(self, f0_hz: np.ndarray, voiced: np.ndarray) -> np.ndarray:
        """Semitones above the running mean of voiced frames (frame t included), 0 where unvoiced. (T,)"""
        semitones = SEMITONES_PER_OCTAVE * np.log2(f0_hz / PITCH_REFERENCE_HZ)
        out = np.zeros(len(f0_hz))
        for t, (value, is_voiced) in enumerate(zip(semitones, voiced, strict=True)):
            if is_voiced:
                self.mean_st += self.rate * (value - self.mean_st)
                out[t] = np.clip(value - self.mean_st, -PITCH_CLIP_ST, PITCH_CLIP_ST)
        return out


class ProsodyChannel:
    """Per-frame prosody columns (module docstring) from windows, their power spectra and frame energies."""

    def __init__(self, sample_rate: int, n_fft: int, taper: np.ndarray, norm: SpeakerNormConfig, fps: float) -> None:
        self.bins = band_bins(sample_rate, n_fft)
        self.taper = taper
        self.levels = SpeakerNormalizer(NUM_BANDS + 1, SpeakerNormConfig(True, norm.time_constant_s), fps)
        self.pitch = PitchTracker(sample_rate, taper, norm.time_constant_s, fps)

    def reset(self) -> None:
        self.levels.reset()
        self.pitch.reset()

    def update(self, spectrum: np.ndarray, power: np.ndarray, energy_db: np.ndarray,
               speaking: np.ndarray) -> dict[str, np.ndarray]:
        """spectrum (T, N + 1) (:func:`padded_spectrum`), power (T, K), energy_db (T,), speaking (T,) →
        {"bands", "energy", "pitch", "voicing"}."""
        f0, voicing = self.pitch.f0_and_voicing(spectrum)
        voiced = (speaking > 0) & (voicing > VOICED_THRESHOLD)  # (T,) speech itself, not the pauses between words
        levels = np.concatenate([band_levels_db(power, self.bins, self.taper), energy_db[:, None]], axis=1)
        levels = self.levels.update(levels, voiced)  # (T, B + 1) dB relative to the voice's running mean
        relative = self.pitch.relative_pitch(f0, voiced)
        return {"bands": levels[:, :-1], "energy": levels[:, -1:], "pitch": relative[:, None],
                "voicing": voicing[:, None]}
