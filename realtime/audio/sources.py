"""Audio sources: one interface, three implementations (microphone, paced file, fast file).

Every source yields :class:`AudioChunk` s of 16 kHz mono float32 with the stream index of their
first sample and its capture time on the injected :class:`Clock`. Time of sample i of a chunk
is ``capture_time + i / 16000``.

- :class:`MicSource`: sounddevice callback ``InputStream``; the callback only copies into a
  bounded :class:`RingBuffer` sized for the worst hiccup measured, timestamped from PortAudio's
  ADC time; the consumer thread resamples from the device rate to 16 kHz (soxr, streaming), skips
  ahead on purpose (counted, said once) when its backlog can no longer be answered in time, watches
  for a stalled or vanished device, and closes the stream with ``abort()`` within a bound.
- :class:`PacedFileSource`: a file replayed at real-time pace (each chunk released when its last
  sample would have been captured); repeatable.
- :class:`FastFileSource`: a file as fast as possible (offline generation); capture times are
  the stream times (``start / 16000``).
"""

from __future__ import annotations

import logging
import threading
from abc import ABC, abstractmethod
from collections.abc import Generator, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import soxr

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, AudioFileReader, make_resampler
from gesturecast.realtime.audio.pcm import AudioConverter
from gesturecast.realtime.audio.portaudio import (
    advancing_adc_time,
    capture_time,
    check_input_rate,
    close_stream,
    device_label,
    import_sounddevice,
    list_input_devices,
    resolve_input_device,
    translate_stream_error,
)
from gesturecast.realtime.audio.ring_buffer import RingBuffer
from gesturecast.realtime.audio.watchdog import DEFAULT_STALL_TIMEOUT_S, StallWatchdog
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.priority import live_switch_interval, raise_thread_priority

logger = logging.getLogger(__name__)

DEFAULT_CHUNK = 512  # 16 kHz samples per yielded chunk (32 ms)
UNPACED_CHUNK = 64_000  # a source read as fast as possible yields four seconds per chunk: the session then makes
# 30 latents per feature burst and pose batch, and one speech-embedding run covers 25 windows (the poses are the same
# at any chunk size; 4 s instead of 1 s saves about a tenth of `generate`'s CPU for 18 MiB more memory)


@dataclass(frozen=True)
class AudioChunk:
    samples: np.ndarray  # (n,) float32, 16 kHz mono
    start_sample: int  # stream index of samples[0]
    capture_time: float  # clock time at which samples[0] was captured


@dataclass(frozen=True)
class SourceStats:
    chunks: int = 0
    samples: int = 0  # 16 kHz samples delivered
    skipped_samples: int = 0  # device-rate samples skipped on purpose: too far behind to answer in time
    skip_aheads: int = 0  # times the consumer (or a full ring) skipped ahead
    device_overflows: int = 0  # callbacks where PortAudio itself reported input overflow
    untimed_blocks: int = 0  # callbacks without a PortAudio ADC timestamp (timed by their arrival instead)


class AudioSource(ABC):
    """Iterate to receive chunks; ``close()`` ends the iteration (also as a context manager)."""

    sample_rate = SAMPLE_RATE

    def __init__(self) -> None:
        self._chunks = 0
        self._samples = 0
        self._stop = threading.Event()

    @abstractmethod
    def __iter__(self) -> Generator[AudioChunk, None, None]:
        """The chunks; closing the generator early releases the source's resources."""

    def close(self) -> None:
        """End the iteration after the current chunk (thread-safe)."""
        self._stop.set()

    def stats(self) -> SourceStats:
        return SourceStats(chunks=self._chunks, samples=self._samples)

    def _count(self, chunk: AudioChunk) -> AudioChunk:
        self._chunks += 1
        self._samples += chunk.samples.shape[0]
        return chunk

    def __enter__(self) -> AudioSource:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def rechunk(blocks: Iterator[np.ndarray], size: int) -> Iterator[tuple[int, np.ndarray]]:
    """Blocks of any length → (start index, exactly ``size`` samples) pairs; the last may be shorter."""
    pending = np.zeros(0, np.float32)
    start = 0
    for block in blocks:
        pending = np.concatenate([pending, block])
        whole = pending.shape[0] // size * size
        for offset in range(0, whole, size):
            yield start + offset, pending[offset : offset + size]
        start += whole
        pending = pending[whole:]
    if pending.shape[0]:
        yield start, pending


class UnpacedSource(AudioSource):
    """16 kHz blocks as fast as possible, re-cut into chunks whose capture times are their stream times."""

    def __init__(self, blocks: Iterable[np.ndarray], chunk_samples: int = UNPACED_CHUNK) -> None:
        super().__init__()
        self.blocks = blocks  # (m,) 16 kHz float32 blocks
        self.chunk_samples = chunk_samples

    def __iter__(self) -> Generator[AudioChunk, None, None]:
        for start, samples in rechunk(iter(self.blocks), self.chunk_samples):
            if self._stop.is_set():
                return
            yield self._count(AudioChunk(samples, start, start / SAMPLE_RATE))


class FastFileSource(UnpacedSource):
    """A file as fast as possible; memory bounded by the reader's block size."""

    def __init__(self, path: str | Path, chunk_samples: int = UNPACED_CHUNK) -> None:
        super().__init__(AudioFileReader(path), chunk_samples)


class ArraySource(UnpacedSource):
    """Samples already in memory ((n,) or (n, C), float or int16, any rate), as fast as possible: converted to
    16 kHz mono at once, then chunked and timed exactly as :class:`FastFileSource` does a file."""

    def __init__(self, samples: np.ndarray, sample_rate: int, chunk_samples: int = UNPACED_CHUNK) -> None:
        converter = AudioConverter()
        converted = np.concatenate([converter.convert_samples(samples, sample_rate), converter.flush()])  # (n,)
        if not converted.shape[0]:
            raise UserError("the audio array holds no samples")
        super().__init__((converted,), chunk_samples)


class PacedFileSource(AudioSource):
    """A file at real-time pace on an injected clock: chunk [s, e) is released at t0 + e / 16000."""

    def __init__(self, path: str | Path, chunk_samples: int = DEFAULT_CHUNK, clock: Clock | None = None) -> None:
        super().__init__()
        self.reader = AudioFileReader(path)
        self.chunk_samples = chunk_samples
        self.clock = clock or MonotonicClock()

    def __iter__(self) -> Generator[AudioChunk, None, None]:
        origin = self.clock.now()
        for start, samples in rechunk(iter(self.reader), self.chunk_samples):
            if self._stop.is_set():
                return
            self.clock.sleep_until(origin + (start + samples.shape[0]) / SAMPLE_RATE)
            yield self._count(AudioChunk(samples, start, origin + start / SAMPLE_RATE))


CATCH_UP_S = 0.25  # the consumer reads up to this much at once, so a backlog is caught up in few session pushes
SKIP_BEHIND_S = 1.0  # audio waiting this long can no longer be answered in time (twice the default latency L)
RING_SECONDS = 4.0  # the skip threshold plus ten times the worst capture hiccup measured (0.29 s, docs/latency.md)


@dataclass(frozen=True)
class MicConfig:
    device: str | None = None  # index or name substring; None = first input device
    sample_rate: int | None = None  # device rate; None = the device's default
    block_size: int = 512  # device frames per callback
    chunk_samples: int = DEFAULT_CHUNK  # device frames per read at least (more when behind); kept at a skip
    ring_seconds: float = RING_SECONDS  # ring-buffer capacity (a write into a full ring skips the oldest audio)
    skip_behind_s: float = SKIP_BEHIND_S  # a backlog longer than this is skipped to the newest chunk
    read_timeout_s: float = 0.1  # consumer wait per read, so close() is noticed promptly
    stall_timeout_s: float = DEFAULT_STALL_TIMEOUT_S  # no samples for this long ends the run (watchdog)


class MicSource(AudioSource):
    """Live microphone through a sounddevice callback stream (mono: the device's first channel)."""

    def __init__(self, config: MicConfig | None = None, clock: Clock | None = None) -> None:
        super().__init__()
        self.config = config or MicConfig()
        self.clock = clock or MonotonicClock()
        self._sd = import_sounddevice()
        self.device = resolve_input_device(self.config.device, list_input_devices())
        self.device_rate = int(self.config.sample_rate or self.device.default_rate)
        check_input_rate(self.device, self.device_rate)
        self.ring = RingBuffer(int(self.config.ring_seconds * self.device_rate))
        self.label = device_label(self.device)
        self._device_overflows = 0
        self._untimed_blocks = 0
        self._skip_said = False
        self._callback_raised = False
        self._last_adc_time = 0.0  # of the newest block with a believable ADC time (PortAudio's stream clock)
        self._stream_ended = threading.Event()  # PortAudio ended the stream on its own (device gone)

    def _callback(self, indata: np.ndarray, frames: int, time_info: object, status: object) -> None:
        """PortAudio thread: copy only (plus a timestamp and an overflow count; its priority raised once)."""
        if not self._callback_raised:
            self._callback_raised = True
            raise_thread_priority()
        adc_time = advancing_adc_time(time_info.inputBufferAdcTime, self._last_adc_time)
        if adc_time <= 0:
            self._untimed_blocks += 1
        else:
            self._last_adc_time = adc_time
        now = self.clock.now()
        self.ring.write(indata[:, 0], capture_time(now, adc_time, time_info.currentTime, frames, self.device_rate))
        if status:
            self._device_overflows += 1

    def __iter__(self) -> Generator[AudioChunk, None, None]:
        resampler = make_resampler(self.device_rate)
        self._stop.clear()
        self._stream_ended.clear()
        self._last_adc_time = 0.0  # a new stream has its own clock
        watchdog = StallWatchdog(self.label, self.clock.now(), self.config.stall_timeout_s)
        stream = self._open_stream()
        try:
            with live_switch_interval():
                self._start(stream)
                yield from self._consume(resampler, watchdog)
        finally:
            close_stream(stream)

    def _open_stream(self) -> object:
        """A sounddevice InputStream on the chosen device, not started yet."""
        try:
            return self._sd.InputStream(
                device=self.device.index,
                channels=1,
                samplerate=self.device_rate,
                blocksize=self.config.block_size,
                dtype="float32",
                callback=self._callback,
                finished_callback=self._stream_ended.set,
            )
        except self._sd.PortAudioError as error:
            raise translate_stream_error(error, self.device, self.device_rate) from error

    def _start(self, stream: object) -> None:
        try:
            stream.start()
        except self._sd.PortAudioError as error:
            raise translate_stream_error(error, self.device, self.device_rate) from error

    def _consume(self, resampler: soxr.ResampleStream | None, watchdog: StallWatchdog) -> Iterator[AudioChunk]:
        produced = 0
        while not self._stop.is_set():
            self._skip_ahead()
            most = max(self.config.chunk_samples, int(CATCH_UP_S * self.device_rate))
            read = self.ring.read(most, timeout=self.config.read_timeout_s)
            if not read.samples.shape[0]:
                self._check_silence(watchdog)
                continue
            watchdog.audio(self.clock.now())
            samples = read.samples if resampler is None else resampler.resample_chunk(read.samples)
            capture = read.write_time + (read.start_index - read.time_index) / self.device_rate
            if samples.shape[0]:
                yield self._count(AudioChunk(samples, produced, capture))
                produced += samples.shape[0]

    def _skip_ahead(self) -> None:
        """A backlog longer than ``skip_behind_s`` is skipped to its newest chunk, on purpose: counted, said once."""
        self.ring.skip_behind(int(self.config.skip_behind_s * self.device_rate), self.config.chunk_samples)
        if self._skip_said:  # said once: no more stats to read on every read
            return
        skipped = self.ring.stats().skipped_samples
        if skipped:
            self._skip_said = True
            logger.warning("the engine fell more than %.1f s behind %s and skipped %.2f s ahead to the newest audio "
                           "(counted as skipped samples; said once)", self.config.skip_behind_s, self.label,
                           skipped / self.device_rate)

    def _check_silence(self, watchdog: StallWatchdog) -> None:
        """No samples in this read: a stream PortAudio has ended means the device is gone; else the watchdog."""
        if self._stream_ended.is_set() and not self._stop.is_set():
            raise UserError(f"{self.label} stopped delivering audio (unplugged, or its sound server went away); "
                            "run `gesturecast devices` and pick one with --device")
        watchdog.silence(self.clock.now())

    def stats(self) -> SourceStats:
        ring = self.ring.stats()
        return SourceStats(
            chunks=self._chunks,
            samples=self._samples,
            skipped_samples=ring.skipped_samples,
            skip_aheads=ring.skips,
            device_overflows=self._device_overflows,
            untimed_blocks=self._untimed_blocks,
        )
