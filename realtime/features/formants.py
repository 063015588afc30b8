"""The first two formants (F1, F2) of short speech windows by linear prediction (pure numpy/scipy, stateless).

Method (the textbook LPC formant tracker, e.g. Rabiner & Schafer, *Digital Processing of Speech
Signals* ch. 8): pre-emphasis ``x[n] - 0.97 x[n-1]`` and a Hamming taper, autocorrelation up to lag
p, the all-pole predictor ``A(z) = 1 - Σ a_k z^-k`` from the Toeplitz normal equations (the
Yule-Walker / Levinson system ``R a = r``), then the roots of ``A``: a root ``ρ e^{jθ}`` is a
resonance at ``θ · fs / 2π`` Hz with bandwidth ``-ln ρ · fs / π`` Hz. Roots with a narrow bandwidth
inside the speech band are formant candidates; the lowest two are F1 and F2.

Each window is handled on its own, so a frame's formants never depend on the batch it came in
(streaming parity).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_toeplitz

PRE_EMPHASIS = 0.97
WHITE_NOISE_CORRECTION = 1.0001  # lifts R[0] slightly so that the normal equations stay well conditioned
SILENT_POWER = 1e-9  # lag-0 autocorrelation below this: no spectrum to analyse


@dataclass(frozen=True)
class FormantConfig:
    sample_rate: int = 16000
    window: int = 512  # samples (32 ms at 16 kHz) ending at the frame's end
    order: int = 18  # predictor order p: fs/1000 + a few poles for the source and radiation tilt
    min_hz: float = 200.0  # below: voicing bar and f0, not F1
    max_hz: float = 3500.0  # above: F3/F4, not needed for five vowels
    max_bandwidth_hz: float = 500.0  # wider poles shape the spectral tilt, they are no formants


class FormantTracker:
    """(T, N) sample windows → (T, 2) F1, F2 in Hz (NaN where fewer than two formants were found)."""

    def __init__(self, config: FormantConfig | None = None) -> None:
        self.config = config or FormantConfig()
        self._taper = np.hamming(self.config.window)  # (W,)

    def track(self, windows: np.ndarray) -> np.ndarray:
        tail = np.asarray(windows, np.float64)[:, -self.config.window :]  # (T, W)
        return np.stack([self._two_lowest(row) for row in tail]) if len(tail) else np.zeros((0, 2))

    def _two_lowest(self, samples: np.ndarray) -> np.ndarray:
        """(W,) samples → (2,) F1, F2 in Hz, or NaNs."""
        found = self.resonances(samples)
        return found[:2] if found.size >= 2 else np.full(2, np.nan)

    def resonances(self, samples: np.ndarray) -> np.ndarray:
        """(W,) samples → the formant candidates in Hz, ascending (possibly none)."""
        cfg = self.config
        emphasised = np.append(samples[0], samples[1:] - PRE_EMPHASIS * samples[:-1]) * self._taper  # (W,)
        lags = np.array([emphasised[: cfg.window - k] @ emphasised[k:] for k in range(cfg.order + 1)])  # (p + 1,)
        if lags[0] < SILENT_POWER:
            return np.zeros(0)
        lags[0] *= WHITE_NOISE_CORRECTION
        predictor = solve_toeplitz(lags[:-1], lags[1:])  # (p,) a_1 … a_p
        roots = np.roots(np.concatenate([[1.0], -predictor]))
        roots = roots[roots.imag > 0]  # one of each conjugate pair
        hz = np.angle(roots) * cfg.sample_rate / (2 * np.pi)
        bandwidth = -np.log(np.abs(roots)) * cfg.sample_rate / np.pi
        keep = (hz > cfg.min_hz) & (hz < cfg.max_hz) & (bandwidth < cfg.max_bandwidth_hz)
        return np.sort(hz[keep])
