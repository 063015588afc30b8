"""Audio blocks from other software (a voice-agent pipeline, a network peer, a library caller) → the pipeline's
16 kHz mono float32.

:class:`AudioConverter` takes blocks at any rate and channel count, one at a time: sample arrays
(:meth:`AudioConverter.convert_samples`: float or int16, ``(n,)`` or ``(n, channels)``) or 16-bit little-endian
interleaved PCM bytes (:meth:`AudioConverter.convert`): channels are averaged to mono (as
:class:`~gesturecast.models.audio.files.AudioFileReader` does) and the rate is converted with the same
streaming soxr resampler as files and microphones (:func:`~gesturecast.models.audio.files.make_resampler`).
When the input rate changes mid-stream, the resampler is flushed and a new one starts (no samples are lost).
"""

from __future__ import annotations

import numpy as np
import soxr

from gesturecast.errors import UserError
from gesturecast.models.audio.files import MAX_FILE_RATE, MIN_FILE_RATE, check_float_scale, make_resampler

PCM16_FULL_SCALE = 32768.0  # int16 → [-1, 1)
PCM16_BYTES = 2
MAX_CHANNELS = 64  # more "channels" than this means the array is (channels, n): refused, not guessed
INTEGER_FULL_SCALE = {np.dtype(np.int16): PCM16_FULL_SCALE, np.dtype(np.int32): 2.0**31}


def pcm16_to_mono(data: bytes, channels: int) -> np.ndarray:
    """Interleaved int16 PCM bytes → (n,) float32 mono in [-1, 1)."""
    if channels < 1 or len(data) % (PCM16_BYTES * channels):
        raise UserError(f"PCM block of {len(data)} bytes does not hold whole 16-bit frames of {channels} channels")
    frames = np.frombuffer(data, dtype="<i2").reshape(-1, channels)  # (n, C)
    return (frames.mean(axis=1, dtype=np.float32) / np.float32(PCM16_FULL_SCALE)).astype(np.float32)  # (n,)


def samples_to_mono(samples: np.ndarray) -> np.ndarray:
    """(n,) or (n, C) float (in [-1, 1]), int16 or int32 samples → (n,) float32 mono (channels averaged); one-line
    UserError for bytes, another shape or type, NaN / infinite samples, or floats at integer scale."""
    if isinstance(samples, (bytes, bytearray, memoryview)):
        raise UserError("audio samples must be an array, not bytes; 16-bit PCM bytes go to "
                        "Stream.push_pcm16(data, sample_rate, channels=1)")
    samples = np.asarray(samples)
    if samples.ndim not in (1, 2) or (samples.ndim == 2 and not 0 < samples.shape[1] <= MAX_CHANNELS):
        raise UserError(f"audio samples must be (n,) or (n, channels) with at most {MAX_CHANNELS} channels, "
                        f"got shape {samples.shape}")
    if samples.dtype in INTEGER_FULL_SCALE:
        samples = samples / INTEGER_FULL_SCALE[samples.dtype]
    elif samples.dtype.kind != "f":
        raise UserError(f"audio samples must be float, int16 or int32, got {samples.dtype}")
    mono = (samples if samples.ndim == 1 else samples.mean(axis=1)).astype(np.float32, copy=False)  # (n,)
    if not np.isfinite(mono).all():
        raise UserError("audio samples hold NaN or infinite values")
    check_float_scale(mono, "audio samples")
    return mono


def check_sample_rate(sample_rate: object) -> int:
    """``sample_rate`` as an int when it is a whole number of Hz in the supported range; UserError otherwise."""
    if isinstance(sample_rate, bool) or not isinstance(sample_rate, (int, np.integer)) or not (
            MIN_FILE_RATE <= sample_rate <= MAX_FILE_RATE):
        raise UserError(f"sample_rate must be a whole number of Hz from {MIN_FILE_RATE} to {MAX_FILE_RATE}, "
                        f"got {sample_rate!r}")
    return int(sample_rate)


class AudioConverter:
    """Blocks at any rate / channel count in, 16 kHz mono float32 out, streaming."""

    def __init__(self) -> None:
        self._rate: int | None = None
        self._resampler: soxr.ResampleStream | None = None

    def convert(self, data: bytes, sample_rate: int, channels: int) -> np.ndarray:
        """Interleaved int16 PCM bytes → (n,) float32 at 16 kHz (may be empty while the resampler fills)."""
        return self._resample(pcm16_to_mono(data, channels), check_sample_rate(sample_rate))

    def convert_samples(self, samples: np.ndarray, sample_rate: int) -> np.ndarray:
        """(m,) or (m, C) samples (:func:`samples_to_mono`) → (n,) float32 at 16 kHz."""
        return self._resample(samples_to_mono(samples), check_sample_rate(sample_rate))

    def _resample(self, mono: np.ndarray, sample_rate: int) -> np.ndarray:
        flushed = np.zeros(0, np.float32)
        if sample_rate != self._rate:
            flushed = self.flush()
            self._rate, self._resampler = sample_rate, make_resampler(sample_rate)
        converted = mono if self._resampler is None else self._resampler.resample_chunk(mono)
        return np.concatenate([flushed, converted]).astype(np.float32, copy=False)  # (n,)

    def flush(self) -> np.ndarray:
        """The samples still inside the resampler (end of stream or a rate change); the next block starts anew."""
        resampler, self._rate, self._resampler = self._resampler, None, None
        if resampler is None:
            return np.zeros(0, np.float32)
        return resampler.resample_chunk(np.zeros(0, np.float32), last=True).astype(np.float32, copy=False)
