"""Audio files → 16 kHz mono float32, in bounded blocks or all at once (one code path).

Any file libsndfile reads (WAV int16/int32/float32, FLAC, OGG, …), any sample rate, any channel
count. Channels are averaged to mono, then resampled with soxr (a band-limited polyphase
resampler, "HQ" quality), streaming, so a 10-minute file never needs to be in memory at once.
:func:`load_audio` is simply the concatenation of :class:`AudioFileReader`'s blocks, so the
offline and the streaming file paths see identical samples.

Bad input policy (each is one-line :class:`UserError`, never a traceback):
- missing, unreadable, or not audio (e.g. a text file renamed ``.wav``);
- empty (no samples);
- a header outside the limits (sample rate :data:`MIN_FILE_RATE`-:data:`MAX_FILE_RATE`, at most
  :data:`MAX_AUDIO_SECONDS` of audio), checked before anything is decoded;
- NaN or ±inf samples: **rejected**, not sanitised. A non-finite sample means the file is
  corrupt; replacing it would silently hide that and bend the log-mel features around it.
Clipped audio (samples at full scale) is accepted with a logged warning: the features are
log-scaled and still meaningful, but the user should know the recording is distorted.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import soundfile
import soxr

from gesturecast.errors import UserError

logger = logging.getLogger(__name__)

SAMPLE_RATE = 16000  # the pipeline's rate: speech content is below 8 kHz
DEFAULT_BLOCK_FRAMES = 65536  # file frames read per block (about 1.4 s at 48 kHz)
CLIP_LEVEL = 0.999  # |x| at or above this counts as a clipped sample
CLIP_WARN_FRACTION = 1e-3  # warn when more than 0.1 % of the samples are clipped
# float samples beyond this are not audio at full scale ±1 but integers stored as floats (int16 speech peaks in the
# thousands): refused, at every door (a file, an array, a pushed block), since they would give other motion
FLOAT_SCALE_LIMIT = 2.0
RESAMPLE_QUALITY = "HQ"
# header limits, checked before anything is decoded: a crafted header cannot make the resampler
# produce gigabytes from a small file (1 Hz -> 16 kHz multiplies every block by 16 000)
MIN_FILE_RATE = 8000  # Hz: telephone speech; lower rates hold no usable speech
MAX_FILE_RATE = 384000  # Hz: the highest rate audio interfaces record at
MAX_AUDIO_SECONDS = 24 * 3600.0  # frames / rate: one day of audio
PACKAGED_SAMPLE = Path(str(resources.files("gesturecast"))) / "samples" / "sample_speech.wav"  # bundled speech


@dataclass
class ReadStats:
    """What the reader saw in the file (before resampling)."""

    file_rate: int = 0
    channels: int = 0
    file_frames: int = 0
    clipped_samples: int = 0

    @property
    def clipped_fraction(self) -> float:
        return self.clipped_samples / max(self.file_frames, 1)


class AudioFileReader:
    """Iterate over a file as 16 kHz mono float32 blocks; memory stays bounded by ``block_frames``."""

    def __init__(self, path: str | Path, block_frames: int = DEFAULT_BLOCK_FRAMES) -> None:
        self.path = Path(path)
        self.block_frames = block_frames
        info = _probe(self.path)
        self.stats = ReadStats(file_rate=info.samplerate, channels=info.channels, file_frames=info.frames)

    @property
    def duration_s(self) -> float:
        return self.stats.file_frames / self.stats.file_rate

    def __iter__(self) -> Iterator[np.ndarray]:
        self.stats.clipped_samples = 0
        resampler = make_resampler(self.stats.file_rate)
        try:
            blocks = soundfile.blocks(str(self.path), blocksize=self.block_frames, dtype="float32", always_2d=True)
            for position, block in enumerate(blocks):
                mono = self._check_block(block, position)  # (n,)
                out = mono if resampler is None else resampler.resample_chunk(mono)
                if out.size:
                    yield out
        except (soundfile.LibsndfileError, RuntimeError) as error:
            raise UserError(f"{self.path}: cannot decode audio ({error})") from error
        if resampler is not None:
            tail = resampler.resample_chunk(np.zeros(0, np.float32), last=True)
            if tail.size:
                yield tail
        self._warn_if_clipped()

    def _check_block(self, block: np.ndarray, position: int) -> np.ndarray:
        """(n, C) file block → (n,) mono; rejects non-finite samples, counts clipped ones."""
        if not np.isfinite(block).all():
            bad = int(np.count_nonzero(~np.isfinite(block)))
            first_s = (position * self.block_frames + int(np.argmax(~np.isfinite(block).all(axis=1)))) / (
                self.stats.file_rate
            )
            raise UserError(
                f"{self.path}: {bad} NaN/inf samples (first at {first_s:.2f} s); the file is corrupt, re-export it"
            )
        check_float_scale(block, f"{self.path}: the samples")
        self.stats.clipped_samples += int(np.count_nonzero(np.abs(block).max(axis=1) >= CLIP_LEVEL))
        return block.mean(axis=1, dtype=np.float32) if block.shape[1] > 1 else block[:, 0]

    def _warn_if_clipped(self) -> None:
        if self.stats.clipped_fraction > CLIP_WARN_FRACTION:
            logger.warning(
                "%s: %.2f%% of the samples are clipped (at full scale); the recording is distorted, "
                "features are still computed",
                self.path,
                100.0 * self.stats.clipped_fraction,
            )


def check_float_scale(samples: np.ndarray, source: str) -> None:
    """Refuse float samples far beyond full scale ±1 (:data:`FLOAT_SCALE_LIMIT`): int16 values stored as floats."""
    peak = float(np.abs(samples).max(initial=0.0))
    if peak > FLOAT_SCALE_LIMIT:
        raise UserError(f"{source} reach {peak:g}, far beyond full scale: float audio is in [-1, 1] "
                        "(int16 values as floats? divide them by 32768, or pass int16)")


def load_audio(path: str | Path) -> np.ndarray:
    """Whole file → (N,) float32 at :data:`SAMPLE_RATE`, mono. Raises UserError on bad input."""
    blocks = list(AudioFileReader(path))
    return np.concatenate(blocks).astype(np.float32, copy=False) if blocks else np.zeros(0, np.float32)


def _probe(path: Path) -> soundfile._SoundFileInfo:
    if not path.is_file():
        raise UserError(f"{path}: no such audio file")
    if path.stat().st_size == 0:
        raise UserError(f"{path}: the file is empty (0 bytes)")
    try:
        info = soundfile.info(str(path))
    except (soundfile.LibsndfileError, RuntimeError) as error:
        raise UserError(f"{path}: not a readable audio file ({_first_line(error)})") from error
    if info.frames <= 0:
        raise UserError(f"{path}: the audio file is empty (no samples)")
    if info.samplerate <= 0 or info.channels <= 0:
        raise UserError(f"{path}: invalid header ({info.samplerate} Hz, {info.channels} channels)")
    if not MIN_FILE_RATE <= info.samplerate <= MAX_FILE_RATE:
        raise UserError(f"{path}: sample rate {info.samplerate} Hz is outside the supported "
                        f"{MIN_FILE_RATE}-{MAX_FILE_RATE} Hz")
    if info.frames / info.samplerate > MAX_AUDIO_SECONDS:
        raise UserError(f"{path}: the header claims {info.frames / info.samplerate / 3600:.1f} h of audio, "
                        f"more than the supported {MAX_AUDIO_SECONDS / 3600:g} h")
    return info


def make_resampler(file_rate: int) -> soxr.ResampleStream | None:
    """A streaming mono resampler from ``file_rate`` to :data:`SAMPLE_RATE` (None when no resampling is needed)."""
    if file_rate == SAMPLE_RATE:
        return None
    return soxr.ResampleStream(file_rate, SAMPLE_RATE, 1, dtype="float32", quality=RESAMPLE_QUALITY)


def _first_line(error: Exception) -> str:
    return str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
