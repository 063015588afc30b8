"""Voice and channel transforms of a 16 kHz mono waveform that keep the words, timing and prosody.

Used twice: by ``gesturecast bench voices`` (fixed transforms, docs/voices.md) and by training
(random draws of the same transforms, :func:`random_voice`), so the runtime front end hears in
training exactly the kind of audio it is tested on. All work on the waveform; the output has the
input's length.

- **pitch** (``pitch_shift``, n semitones, formants kept): librosa's phase-vocoder pitch shift
  (time-stretch by 2^(-n/12), then soxr resampling back), which moves the whole spectrum; then,
  per STFT frame, the spectral envelope of the shifted signal is replaced by the original's
  (multiplied by E_x / E_y), so the harmonics move by 2^(n/12) and the formants stay.
- **formant** (``formant_shift``, factor a, pitch kept): per STFT frame the spectral envelope is
  warped along frequency, E'(f) = E(f / a), and the fine structure (the harmonics) is kept:
  S' = S · E(f / a) / E(f). a > 1 is a shorter vocal tract (formants up, e.g. adult → child),
  a < 1 a longer one.
- The spectral envelope E is the cepstrally smoothed magnitude (Oppenheim & Schafer): the real
  cepstrum of log |S| keeps its first ``ENVELOPE_LIFTER`` quefrency coefficients (1.9 ms, below the
  2.5 ms period of a 400 Hz voice), the rest is zeroed.
- **gain** (dB): a plain multiplication (samples may exceed ±1: nothing is clipped).
- **noise** (SNR dB): white Gaussian noise whose power is the clip's mean power / 10^(SNR / 10).
- **telephone**: 4th-order Butterworth band-pass 300-3400 Hz applied forwards and backwards
  (scipy ``sosfiltfilt``: zero phase, so nothing is delayed; the effective order is 8).
- **reverb** (small room): convolution with a synthetic impulse response: the direct path (1 at
  t = 0) plus, from 2.5 ms on, Gaussian noise with an exponential decay reaching −60 dB at
  ``rt60_s`` (0.35 s), scaled to a direct-to-reverberant energy ratio of ``drr_db`` (0 dB); the
  result is rescaled to the input's RMS.
- **eq** (augmentation only): a smooth random gain curve over frequency (a tilt plus three
  cosines, in dB) multiplied into the STFT.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

N_FFT = 1024  # 64 ms at 16 kHz: resolves harmonics of voices down to ~60 Hz
HOP = 256
ENVELOPE_LIFTER = 30  # quefrency samples kept (1.9 ms)
MAGNITUDE_FLOOR = 1e-8
TELEPHONE_BAND_HZ = (300.0, 3400.0)
TELEPHONE_ORDER = 4
REVERB_PREDELAY_S = 0.0025
DECAY_DB = 60.0


def _stft(audio: np.ndarray) -> np.ndarray:
    import librosa

    return librosa.stft(audio.astype(np.float32), n_fft=N_FFT, hop_length=HOP)  # (K, T') complex


def _istft(spectrum: np.ndarray, length: int) -> np.ndarray:
    import librosa

    return librosa.istft(spectrum, hop_length=HOP, n_fft=N_FFT, length=length).astype(np.float32)


def spectral_envelope(magnitude: np.ndarray) -> np.ndarray:
    """(K, T') magnitudes → (K, T') cepstrally smoothed envelope (module docstring)."""
    cepstrum = np.fft.irfft(np.log(np.maximum(magnitude, MAGNITUDE_FLOOR)), axis=0)  # (N, T')
    cepstrum[ENVELOPE_LIFTER : cepstrum.shape[0] - ENVELOPE_LIFTER + 1] = 0.0
    return np.exp(np.fft.rfft(cepstrum, axis=0).real)  # (K, T')


def warp_frequency(envelope: np.ndarray, factor: float) -> np.ndarray:
    """(K, T') → (K, T'): E'(f) = E(f / factor), linear interpolation, the edge bins held."""
    bins = np.arange(envelope.shape[0], dtype=np.float64)
    source = np.clip(bins / factor, 0.0, bins[-1])
    low = np.floor(source).astype(int)
    high = np.minimum(low + 1, len(bins) - 1)
    weight = (source - low)[:, None]
    return envelope[low] * (1.0 - weight) + envelope[high] * weight


def pitch_shift(audio: np.ndarray, sample_rate: int, semitones: float) -> np.ndarray:
    """Move the pitch by ``semitones`` and keep the formants (module docstring)."""
    import librosa

    shifted = librosa.effects.pitch_shift(audio.astype(np.float32), sr=sample_rate, n_steps=semitones,
                                          res_type="soxr_hq")
    original, moved = _stft(audio), _stft(shifted)
    correction = spectral_envelope(np.abs(original)) / spectral_envelope(np.abs(moved))  # (K, T')
    return _istft(moved * correction, len(audio))


def formant_shift(audio: np.ndarray, factor: float) -> np.ndarray:
    """Scale the formant frequencies by ``factor`` and keep the pitch (module docstring)."""
    spectrum = _stft(audio)
    envelope = spectral_envelope(np.abs(spectrum))
    return _istft(spectrum * (warp_frequency(envelope, factor) / envelope), len(audio))


def apply_gain(audio: np.ndarray, gain_db: float) -> np.ndarray:
    return (audio * 10.0 ** (gain_db / 20.0)).astype(np.float32)


def add_white_noise(audio: np.ndarray, snr_db: float, rng: np.random.Generator) -> np.ndarray:
    """White noise at ``snr_db`` below the clip's mean power."""
    power = float(np.mean(audio.astype(np.float64) ** 2))
    noise = rng.standard_normal(len(audio)) * np.sqrt(power / 10.0 ** (snr_db / 10.0))
    return (audio + noise).astype(np.float32)


def telephone_band(audio: np.ndarray, sample_rate: int) -> np.ndarray:
    import scipy.signal  # here, not at the top: importing scipy takes seconds that a command's help never needs

    sos = scipy.signal.butter(TELEPHONE_ORDER, TELEPHONE_BAND_HZ, btype="bandpass", fs=sample_rate, output="sos")
    return scipy.signal.sosfiltfilt(sos, audio.astype(np.float64)).astype(np.float32)


def room_impulse_response(sample_rate: int, rt60_s: float, drr_db: float, rng: np.random.Generator) -> np.ndarray:
    """Direct path + exponentially decaying noise tail (module docstring). (L,) float64."""
    length = int(rt60_s * sample_rate)
    start = int(REVERB_PREDELAY_S * sample_rate)
    times = np.arange(length - start) / sample_rate
    tail = rng.standard_normal(length - start) * 10.0 ** (-DECAY_DB / 20.0 * times / rt60_s)
    tail *= np.sqrt(10.0 ** (-drr_db / 10.0) / np.sum(tail**2))  # tail energy vs the direct path's 1
    response = np.zeros(length)
    response[0] = 1.0
    response[start:] = tail
    return response


def reverb(audio: np.ndarray, sample_rate: int, rng: np.random.Generator, rt60_s: float = 0.35,
           drr_db: float = 0.0) -> np.ndarray:
    """Small-room reverb, rescaled to the input's RMS."""
    import scipy.signal

    wet = scipy.signal.fftconvolve(audio.astype(np.float64), room_impulse_response(sample_rate, rt60_s, drr_db, rng))
    wet = wet[: len(audio)]
    scale = np.sqrt(np.mean(audio.astype(np.float64) ** 2) / max(np.mean(wet**2), 1e-20))
    return (wet * scale).astype(np.float32)


def random_eq(audio: np.ndarray, sample_rate: int, rng: np.random.Generator, tilt_db: float = 6.0,
              ripple_db: float = 3.0) -> np.ndarray:
    """A smooth random gain curve over frequency: tilt ± ``tilt_db`` plus three cosines of ± ``ripple_db``."""
    position = np.linspace(-0.5, 0.5, N_FFT // 2 + 1)  # (K,) 0 Hz … Nyquist
    curve = rng.uniform(-tilt_db, tilt_db) * position
    for component in range(1, 4):
        curve += rng.uniform(-ripple_db, ripple_db) * np.cos(np.pi * component * (position + 0.5)
                                                             + rng.uniform(0, 2 * np.pi))
    return _istft(_stft(audio) * 10.0 ** (curve[:, None] / 20.0), len(audio))


@dataclass(frozen=True)
class VoiceAugmentConfig:
    """Ranges of :func:`random_voice` (training-time waveform augmentation)."""

    pitch_probability: float = 0.7
    pitch_semitones: float = 6.0  # uniform ± this
    formant_probability: float = 0.5
    formant_factor: tuple[float, float] = (0.85, 1.18)  # log-uniform
    gain_db: tuple[float, float] = (-25.0, 6.0)
    noise_probability: float = 0.4
    snr_db: tuple[float, float] = (10.0, 40.0)
    reverb_probability: float = 0.3
    rt60_s: tuple[float, float] = (0.2, 0.6)
    telephone_probability: float = 0.15


def random_voice(audio: np.ndarray, sample_rate: int, rng: np.random.Generator,
                 config: VoiceAugmentConfig | None = None) -> np.ndarray:
    """One random new voice and channel for ``audio``: pitch, formants, EQ, band, reverb, noise, gain."""
    cfg = config or VoiceAugmentConfig()
    out = audio.astype(np.float32)
    if rng.random() < cfg.pitch_probability:
        out = pitch_shift(out, sample_rate, rng.uniform(-cfg.pitch_semitones, cfg.pitch_semitones))
    if rng.random() < cfg.formant_probability:
        out = formant_shift(out, float(np.exp(rng.uniform(*np.log(cfg.formant_factor)))))
    out = random_eq(out, sample_rate, rng)
    if rng.random() < cfg.telephone_probability:
        out = telephone_band(out, sample_rate)
    if rng.random() < cfg.reverb_probability:
        out = reverb(out, sample_rate, rng, rt60_s=rng.uniform(*cfg.rt60_s))
    if rng.random() < cfg.noise_probability:
        out = add_white_noise(out, rng.uniform(*cfg.snr_db), rng)
    return apply_gain(out, rng.uniform(*cfg.gain_db))
