"""Raw PCM blocks from other software (a voice-agent pipeline, a network peer) → the pipeline's 16 kHz mono float32.

:class:`PcmConverter` takes 16-bit little-endian interleaved PCM at any rate and channel count, one block
at a time: channels are averaged to mono (as :class:`~gesturecast.realtime.audio.files.AudioFileReader`
does) and the rate is converted with the same streaming soxr resampler as files and microphones
(:func:`~gesturecast.realtime.audio.files.make_resampler`). When the input rate changes mid-stream, the
resampler is flushed and a new one starts (no samples are lost).
"""

from __future__ import annotations

import numpy as np
import soxr

from gesturecast.errors import UserError
from gesturecast.realtime.audio.files import make_resampler

PCM16_FULL_SCALE = 32768.0  # int16 → [-1, 1)
PCM16_BYTES = 2


def pcm16_to_mono(data: bytes, channels: int) -> np.ndarray:
    """Interleaved int16 PCM bytes → (n,) float32 mono in [-1, 1)."""
    if channels < 1 or len(data) % (PCM16_BYTES * channels):
        raise UserError(f"PCM block of {len(data)} bytes does not hold whole 16-bit frames of {channels} channels")
    frames = np.frombuffer(data, dtype="<i2").reshape(-1, channels)  # (n, C)
    return (frames.mean(axis=1, dtype=np.float32) / np.float32(PCM16_FULL_SCALE)).astype(np.float32)  # (n,)


class PcmConverter:
    """Blocks of int16 PCM at any rate / channel count in, 16 kHz mono float32 out, streaming."""

    def __init__(self) -> None:
        self._rate: int | None = None
        self._resampler: soxr.ResampleStream | None = None

    def convert(self, data: bytes, sample_rate: int, channels: int) -> np.ndarray:
        """(n,) float32 at 16 kHz for this block (may be empty while the resampler fills)."""
        mono = pcm16_to_mono(data, channels)  # (m,)
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
