"""The first two formants (F1, F2) of short speech windows by linear prediction (pure numpy, stateless).

Method (the textbook LPC formant tracker, e.g. Rabiner & Schafer, *Digital Processing of Speech
Signals* ch. 8): pre-emphasis ``x[n] - 0.97 x[n-1]`` and a Hamming taper; the autocorrelation
``r[0..p]`` (as the inverse FFT of the power spectrum, zero-padded so it is not circular); the all-pole
predictor ``A(z) = 1 - Σ a_k z^-k`` from the normal equations ``R a = r`` by the Levinson-Durbin
recursion; then the roots of ``A`` (eigenvalues of its companion matrix): a root ``ρ e^{jθ}`` is a
resonance at ``θ · fs / 2π`` Hz with bandwidth ``-ln ρ · fs / π`` Hz. Roots with a narrow bandwidth
inside the speech band are formant candidates; the lowest two are F1 and F2.

All steps run on a batch of frames at once, but each frame's arithmetic only reads its own row (row-wise
FFTs, element-wise recursion, one eigenvalue problem per frame), so a frame's formants never depend on
the batch it came in (streaming parity).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PRE_EMPHASIS = 0.97
WHITE_NOISE_CORRECTION = 1.0001  # lifts r[0] slightly so that the recursion stays well conditioned
SILENT_POWER = 1e-9  # r[0] below this: no spectrum to analyse
FORMANTS = 2


@dataclass(frozen=True)
class FormantConfig:
    sample_rate: int = 16000
    window: int = 512  # samples (32 ms at 16 kHz) ending at the frame's end
    order: int = 18  # predictor order p: fs/1000 + a few poles for the source and radiation tilt
    min_hz: float = 200.0  # below: voicing bar and f0, not F1
    max_hz: float = 3500.0  # above: F3/F4, not needed for five vowels
    max_bandwidth_hz: float = 500.0  # wider poles shape the spectral tilt, they are no formants


class FormantTracker:
    """(T, N ≥ window) sample windows → (T, 2) F1, F2 in Hz (NaN where fewer than two formants were found)."""

    def __init__(self, config: FormantConfig | None = None) -> None:
        self.config = config or FormantConfig()
        self._taper = np.hamming(self.config.window)  # (W,)
        self._fft_size = 2 * self.config.window  # no wrap-around for lags < window

    def track(self, windows: np.ndarray) -> np.ndarray:
        tail = np.asarray(windows, np.float64)[:, -self.config.window :]  # (T, W)
        lags = self.autocorrelation(tail)  # (T, p + 1)
        audible = lags[:, 0] >= SILENT_POWER  # (T,)
        lags[~audible] = np.eye(1, lags.shape[1])  # a white spectrum: a harmless predictor, discarded below
        hz = self.resonances(levinson_durbin(lags))  # (T, p // 2 + …) ascending, inf where none
        formants = hz[:, :FORMANTS]  # (T, 2)
        return np.where(audible[:, None] & np.isfinite(formants).all(axis=1, keepdims=True), formants, np.nan)

    def autocorrelation(self, samples: np.ndarray) -> np.ndarray:
        """(T, W) → (T, p + 1) autocorrelation of the pre-emphasised, tapered windows."""
        emphasised = np.concatenate([samples[:, :1], samples[:, 1:] - PRE_EMPHASIS * samples[:, :-1]], axis=1)
        spectrum = np.fft.rfft(emphasised * self._taper, n=self._fft_size, axis=-1)  # (T, K)
        power = spectrum.real**2 + spectrum.imag**2
        lags = np.fft.irfft(power, n=self._fft_size, axis=-1)[:, : self.config.order + 1]  # (T, p + 1)
        lags[:, 0] *= WHITE_NOISE_CORRECTION
        return lags

    def resonances(self, predictor: np.ndarray) -> np.ndarray:
        """(T, p) predictor a_1 … a_p → (T, p) candidate formants in Hz, ascending, inf-padded."""
        cfg = self.config
        frames, order = predictor.shape
        companion = np.zeros((frames, order, order))  # (T, p, p): eigenvalues = roots of A(z)
        companion[:, 0, :] = predictor
        companion[:, np.arange(1, order), np.arange(order - 1)] = 1.0
        roots = np.linalg.eigvals(companion)  # (T, p) complex
        hz = np.angle(roots) * cfg.sample_rate / (2 * np.pi)
        bandwidth = -np.log(np.maximum(np.abs(roots), np.finfo(float).tiny)) * cfg.sample_rate / np.pi
        keep = (roots.imag > 0) & (hz > cfg.min_hz) & (hz < cfg.max_hz) & (bandwidth < cfg.max_bandwidth_hz)
        return np.sort(np.where(keep, hz, np.inf), axis=1)


def levinson_durbin(lags: np.ndarray) -> np.ndarray:
    """(T, p + 1) autocorrelation → (T, p) predictor a with x[n] ≈ Σ a_k x[n-k] (element-wise over frames)."""
    order = lags.shape[1] - 1
    predictor = np.zeros((lags.shape[0], order))  # (T, p)
    error = lags[:, 0].copy()  # (T,) prediction error power
    for i in range(order):
        reflection = (lags[:, i + 1] - (predictor[:, :i] * lags[:, i:0:-1]).sum(axis=1)) / error  # (T,)
        previous = predictor[:, :i].copy()  # a_1 … a_i of order i
        predictor[:, :i] = previous - reflection[:, None] * previous[:, ::-1]
        predictor[:, i] = reflection
        error *= 1.0 - reflection**2
    return predictor
