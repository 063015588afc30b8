"""Pure numpy signal-processing pieces of the speech features (no state, float64 inside).

Every function works on a batch of frames and treats each frame independently, so a frame's
value never depends on how many other frames were computed with it (streaming parity).
"""

from __future__ import annotations

import numpy as np

POWER_FLOOR = 1e-10  # -100 dB: floor for mel power (full-scale sine ≈ 0 dB after normalisation)
RMS_FLOOR = 1e-5  # -100 dB: floor for frame RMS
DB_PER_POWER_DECADE = 10.0
DB_PER_AMPLITUDE_DECADE = 20.0
SLANEY_LINEAR_HZ_PER_MEL = 200.0 / 3.0  # Slaney mel scale: linear below 1 kHz …
SLANEY_BREAK_HZ = 1000.0
SLANEY_LOG_STEP = np.log(6.4) / 27.0  # … logarithmic above it


def frame_boundary(k: np.ndarray | int, sample_rate: int, fps: int) -> np.ndarray | int:
    """First sample of frame k: floor(k * sample_rate / fps), exact in integers.

    Frame k covers samples [frame_boundary(k), frame_boundary(k + 1)); at 16 kHz and 30 fps
    frames are 533 or 534 samples long and never drift from k/30 s by more than one sample.
    """
    return (k * sample_rate) // fps


def frames_complete(total_samples: int, sample_rate: int, fps: int) -> int:
    """Number of frames whose last sample is among the first ``total_samples`` samples.

    Largest m with frame_boundary(m) <= total_samples:  m * sr < (total + 1) * fps.
    """
    return ((total_samples + 1) * fps - 1) // sample_rate


def hz_to_mel(hz: np.ndarray) -> np.ndarray:
    """Slaney mel scale (librosa's default, ``htk=False``)."""
    hz = np.asarray(hz, np.float64)
    linear = hz / SLANEY_LINEAR_HZ_PER_MEL
    break_mel = SLANEY_BREAK_HZ / SLANEY_LINEAR_HZ_PER_MEL
    log_part = break_mel + np.log(np.maximum(hz, SLANEY_BREAK_HZ) / SLANEY_BREAK_HZ) / SLANEY_LOG_STEP
    return np.where(hz >= SLANEY_BREAK_HZ, log_part, linear)


def mel_to_hz(mel: np.ndarray) -> np.ndarray:
    mel = np.asarray(mel, np.float64)
    break_mel = SLANEY_BREAK_HZ / SLANEY_LINEAR_HZ_PER_MEL
    log_part = SLANEY_BREAK_HZ * np.exp(SLANEY_LOG_STEP * (mel - break_mel))
    return np.where(mel >= break_mel, log_part, mel * SLANEY_LINEAR_HZ_PER_MEL)


def mel_filterbank(sample_rate: int, n_fft: int, n_mels: int, fmin: float, fmax: float) -> np.ndarray:
    """(n_mels, n_fft // 2 + 1) triangular filters, Slaney area normalisation (= librosa.filters.mel)."""
    fft_hz = np.linspace(0.0, sample_rate / 2.0, n_fft // 2 + 1)  # (K,)
    edges_hz = mel_to_hz(np.linspace(hz_to_mel(fmin), hz_to_mel(fmax), n_mels + 2))  # (M + 2,)
    widths = np.diff(edges_hz)  # (M + 1,)
    ramps = edges_hz[:, None] - fft_hz[None, :]  # (M + 2, K)
    lower = -ramps[:-2] / widths[:-1, None]  # (M, K)
    upper = ramps[2:] / widths[1:, None]  # (M, K)
    weights = np.maximum(0.0, np.minimum(lower, upper))  # (M, K)
    return weights * (2.0 / (edges_hz[2:] - edges_hz[:-2]))[:, None]


def power_spectrum(windows: np.ndarray, taper: np.ndarray) -> np.ndarray:
    """(T, N) sample windows → (T, N // 2 + 1) power |FFT|^2 of the tapered windows."""
    spectrum = np.fft.rfft(windows.astype(np.float64) * taper, axis=-1)  # (T, K)
    return spectrum.real**2 + spectrum.imag**2


def mel_db(power: np.ndarray, filterbank: np.ndarray) -> np.ndarray:
    """(T, K) power → (T, M) log-mel in dB; row by row so that batch size cannot change a bit."""
    mel = np.stack([filterbank @ row for row in power]) if power.shape[0] else np.zeros((0, filterbank.shape[0]))
    return DB_PER_POWER_DECADE * np.log10(np.maximum(mel, POWER_FLOOR))  # (T, M)


def spectral_flux(mel_db_frames: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """Onset strength: mean over bands of the positive dB rise since the previous frame.

    (T, M) and previous (M,) → (T,). Same definition as librosa.onset.onset_strength with
    lag 1 and mean aggregation, but computed causally (frame k vs frame k - 1).
    """
    stacked = np.concatenate([previous[None, :], mel_db_frames])  # (T + 1, M)
    return np.maximum(0.0, np.diff(stacked, axis=0)).mean(axis=1)  # (T,)


def segment_rms_db(samples: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """RMS in dB of consecutive segments: samples (S,), offsets (T + 1,) into samples → (T,)."""
    start = offsets[0]
    squares = samples[start : offsets[-1]].astype(np.float64) ** 2  # only the segments' samples
    sums = np.array([squares[a - start : b - start].sum() for a, b in zip(offsets[:-1], offsets[1:], strict=True)])
    rms = np.sqrt(sums / np.diff(offsets))
    return DB_PER_AMPLITUDE_DECADE * np.log10(np.maximum(rms, RMS_FLOOR))


def segment_ac_rms_db(samples: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """RMS in dB of consecutive segments with each segment's mean (its DC offset) removed → (T,).

    A DC offset (a cheap interface, a miscalibrated converter) adds a constant level to every frame: 0.02 of
    full scale is −34 dBFS, louder than quiet speech. What is left after removing it is the signal's
    alternating part, the level a voice-activity decision needs.
    """
    segments = [samples[a:b].astype(np.float64) for a, b in zip(offsets[:-1], offsets[1:], strict=True)]
    rms = np.sqrt(np.array([np.mean((segment - segment.mean()) ** 2) for segment in segments]))
    return DB_PER_AMPLITUDE_DECADE * np.log10(np.maximum(rms, RMS_FLOOR))
