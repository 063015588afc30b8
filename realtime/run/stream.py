"""``gesturecast.Stream``: audio pushed in by the caller, pose frames out, in real time.

The same engine as ``gesturecast live``: a :class:`GestureSession` built from :class:`Settings`, warmed up
before the first block (:func:`warm_up`), its frames released to the outputs at capture time + L by a
:class:`FrameRelease` (the live engine's scheduler worker). What differs is who owns the audio: here the
caller pushes blocks (a robot's microphone, a game's voice chat, a TTS engine, a voice-agent pipeline)
instead of the engine reading a source.

- :meth:`Stream.push` takes a block at any rate and channel count (float or int16, ``(n,)`` or ``(n, C)``),
  converts it to 16 kHz mono with the files' streaming resampler, times it as it is heard (a block starts when
  it arrives or where the previous block ends, whichever is later: TTS audio arrives faster than it plays)
  and returns the pose frames it completed at once, *before* they are due (not paced: for recording, or for a
  program that schedules them itself by ``presentation_time``, on ``time.monotonic``).
- Paced, each frame handed over at its presentation time, as the outputs get it: ``on_frame`` (a callback, on
  the release thread), :meth:`Stream.frames` (``for frame in ...``, blocking) and :meth:`Stream.aframes`
  (``async for frame in ...``, in an asyncio program); the last two end when the stream is closed.
- :meth:`Stream.control` changes style, part styles, guidance, γ or root mode, blended in (no pop).
- :meth:`Stream.close` ends the stream: the look-ahead's last poses, every frame released on time, the
  outputs closed (a BVH recording is written then). A ``with`` block closes it; an exception stops it at once.
  A stream still open when Python exits is closed then, with a warning naming its recording: what was recorded is
  kept.

Any thread may push, send words or close: those calls take the stream one at a time (:func:`one_at_a_time`), so
blocks pushed from two threads at once are heard one after the other, never interleaved inside the session.
"""

from __future__ import annotations

import atexit
import functools
import logging
import threading
from collections.abc import Callable

import numpy as np

from gesturecast.bridges.output_settings import Outputs
from gesturecast.controls import SENTENCE_TEXT, STREAM_TIME, Word, parse_controls, parse_words
from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.audio.pcm import AudioConverter
from gesturecast.realtime.audio.sources import AudioChunk, SourceStats
from gesturecast.realtime.gestures.cues import played
from gesturecast.realtime.run.engine import EngineReport, FrameRelease, make_report, warm_up
from gesturecast.realtime.run.engine_setup import build_outputs, build_session
from gesturecast.realtime.run.paced import AsyncFrameFeed, FeedSet, FrameFeed
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.scheduler import SchedulerConfig
from gesturecast.settings import Settings, with_overrides

logger = logging.getLogger(__name__)

FrameCallback = Callable[[PoseFrame], None]
SPOKEN_WORD_S = 0.35  # a word's share of a sentence given without word times (about 170 words a minute)


def one_at_a_time(method: Callable) -> Callable:
    """A :class:`Stream` method that holds the stream's lock while it runs (the session is not thread-safe)."""

    @functools.wraps(method)
    def locked(self: Stream, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)

    return locked


class AudioTimeline:
    """Stream sample indices and capture times of audio that is played back to back."""

    def __init__(self) -> None:
        self.samples = 0
        self._end_time = float("-inf")
        self._last: tuple[int, float] | None = None  # (first sample, capture time) of the newest chunk

    def chunk(self, samples: np.ndarray, now: float) -> AudioChunk:
        """The chunk of (n,) samples arriving at ``now``: it starts now, or where the previous one ends."""
        start_time = max(now, self._end_time)
        chunk = AudioChunk(samples, self.samples, start_time)
        self._last = (self.samples, start_time)
        self.samples += samples.shape[0]
        self._end_time = start_time + samples.shape[0] / SAMPLE_RATE
        return chunk

    def stream_time(self, instant: float, now: float) -> float:
        """Stream seconds of the audio heard at clock time ``instant`` (past the pushed audio: as if it went on;
        before any audio: as if it started ``now``)."""
        sample, time = self._last or (0, now)
        return max(sample / SAMPLE_RATE + instant - time, 0.0)


class Stream:
    """One live stream driven by pushed audio (see the module docstring).

    settings: how to generate (default ``Settings()``); keyword ``overrides`` change single fields
        (``Stream(style="happy")``).
    outputs: where frames go besides the caller (VMC, OSC, WebSocket viewer, BVH); default none.
    on_frame: called with each frame at its presentation time (from the release thread): paced, as are
        :meth:`frames` and :meth:`aframes`; :meth:`push` returns frames before they are due.
    paced: release at capture time + L (True) or as soon as generated (False: frames are stamped in stream
        time, as ``generate`` does).
    warm: run every stage once on throwaway audio first, so the first frames are on time.
    """

    def __init__(self, settings: Settings | None = None, outputs: Outputs | None = None, *,
                 on_frame: FrameCallback | None = None, clock: Clock | None = None, paced: bool = True,
                 warm: bool = True, **overrides) -> None:
        self.settings = with_overrides(settings, overrides)
        self.outputs = outputs or Outputs()
        self.clock = clock or MonotonicClock()
        self.paced = paced
        self._lock = threading.RLock()  # push, words, close: one thread at a time in the session
        self.session = build_session(self.settings, self.clock)
        if paced:  # live: the words' work never delays a frame (unpaced: decided at once, as offline)
            self.session.gestures.start_worker()
        self.bridges = build_outputs(self.outputs, self.settings, self.session, self.clock)
        self._on_frame = on_frame
        self._release = FrameRelease(self.session, self._send, self.clock,
                                     SchedulerConfig(output_fps=float(self.settings.fps), paced=paced))
        self._converter = AudioConverter()
        self._timeline = AudioTimeline()
        self._flushed_end = 0  # stream samples at the end of the last flush's silence
        self._closed = False
        self._feeds = FeedSet()
        self.warm_up_s = warm_up(self.session, self.clock) if warm else 0.0
        self._release.start()
        atexit.register(self._close_at_exit)

    @property
    def latency_ms(self) -> float:
        """L: a frame answering audio heard at time t is presented at t + L (delay your audio by this much)."""
        return self.session.budget.total_ms

    @property
    def viseme_names(self) -> tuple[str, ...]:
        """Names of ``PoseFrame.visemes`` (VRM 0.x or 1.0 presets), () with lip sync off."""
        return self.session.viseme_names

    @property
    def audio_seconds(self) -> float:
        """Seconds of audio pushed so far."""
        return self._timeline.samples / SAMPLE_RATE

    @one_at_a_time
    def push(self, samples: np.ndarray, sample_rate: int = SAMPLE_RATE) -> list[PoseFrame]:
        """Feed one block: a numpy array (n,) or (n, channels), float in [-1, 1] or int16, at ``sample_rate`` Hz;
        returns the pose frames it completed, as they become ready (often none: one latent of d frames at a time,
        once the look-ahead's audio after it has arrived). The last frames of the audio pushed so far come from
        :meth:`flush` (the stream goes on) or :meth:`close` (it ends). Floats far beyond ±1 (int16 values as
        floats) are refused, as bytes are (they go to :meth:`push_pcm16`)."""
        self._check_open()
        return self._generate(self._converter.convert_samples(samples, sample_rate))

    def frames(self) -> FrameFeed:
        """The frames released from now on, each when it is due (its ``presentation_time``): ``for frame in
        stream.frames()`` blocks until the next one and ends when the stream is closed (push audio from another
        thread, or use ``on_frame``)."""
        return self._feeds.open(FrameFeed())

    def aframes(self) -> AsyncFrameFeed:
        """:meth:`frames` for asyncio: ``async for frame in stream.aframes()``, opened inside the event loop that
        reads it (push audio with ``await asyncio.to_thread(stream.push, ...)``)."""
        return self._feeds.open(AsyncFrameFeed())

    @one_at_a_time
    def push_pcm16(self, data: bytes, sample_rate: int, channels: int = 1) -> list[PoseFrame]:
        """:meth:`push` for 16-bit little-endian PCM bytes (what voice pipelines and network peers send), at
        ``sample_rate`` Hz, ``channels`` interleaved (frame by frame: left, right, left, …; averaged to mono)."""
        self._check_open()
        return self._generate(self._converter.convert(data, sample_rate, channels))

    @one_at_a_time
    def say(self, text: str, samples: np.ndarray, sample_rate: int = SAMPLE_RATE) -> list[PoseFrame]:
        """A sentence and its own speech together (a TTS service's sentence text and the audio it made of it): the
        words are placed on that speech (aligned as far as their cues need) and their gestures cued before it is
        pushed, so each stroke lands on its word; then the audio is pushed as :meth:`push` pushes it, and its frames
        are returned."""
        self._check_open()
        return self._say(text, self._converter.convert_samples(samples, sample_rate))

    @one_at_a_time
    def say_pcm16(self, text: str, data: bytes, sample_rate: int, channels: int = 1) -> list[PoseFrame]:
        """:meth:`say` for 16-bit little-endian PCM bytes, as :meth:`push_pcm16` takes them."""
        self._check_open()
        return self._say(text, self._converter.convert(data, sample_rate, channels))

    def control(self, control: dict | None = None, **changes) -> None:
        """Change style, prompt, style2, part_styles, gamma, style_strength, guidance, audio_guidance, root, intensity
        (gesture size 0..2) or pause (True: the idle, breathing pose), blended in from the next latent, or cue a
        ``gesture`` or ``words`` (thread-safe). The fields are checked here, by the
        same check as a WebSocket control message, and refused in the same one-line words (UserError); so is a style
        or gesture the model does not know."""
        self._check_open()
        self.session.controls.submit(parse_controls({**(control or {}), **changes}))

    @one_at_a_time
    def words(self, words: list[dict]) -> int:
        """Words with stream-time stamps (``[{"word", "start", "end"}]``, seconds since the first pushed sample), e.g.
        a TTS service's word timings sent before the audio plays: speech acts cue their gestures with the stroke on the
        word (a quicker approach when the word's window is already generated); words more than five minutes ahead of
        the stream are refused (one line). Checked as a ``words`` message is; returns the cues that play."""
        self._check_open()
        (checked,) = parse_controls({"words": words})
        self.session.gestures.check_live_words(checked.words)
        return played(self.session.gestures.hear_words(checked.words))

    @one_at_a_time
    def spoken(self, text: str, start: float | None = None, end: float | None = None) -> int:
        """Text a TTS service speaks or a listener said, without word times. One word with ``start`` is a word a TTS
        service reports as it speaks it (placed at ``start``). Anything else is a sentence: its words get their times
        from its own speech, forced-aligned once that audio has arrived (the stream keeps its last 30 s, so text that
        comes after its audio is placed too): its speech begins at ``start`` (stream time) when given, else at the
        first voiced audio after the previous sentence's end; it ends by ``end`` when given, else at the first pause
        after about its length. A speech act cues its gesture once the words after it that tell have arrived. Returns
        the cues that play now (a sentence whose audio is still to come plays its cues when it arrives)."""
        self._check_open()
        start = None if start is None else STREAM_TIME.check("start", start)
        end = None if end is None else STREAM_TIME.check("end", end)
        tokens = SENTENCE_TEXT.check("text", text).split() if text.strip() else []
        if start is not None and end is None and len(tokens) == 1:
            return sum(played(self.session.gestures.hear_spoken(word)) for word in spoken_words(text, start))
        return played(self.session.gestures.hear_sentence(" ".join(tokens), start, end)) if tokens else 0

    @one_at_a_time
    def end_of_words(self) -> int:
        """The words reported by :meth:`spoken` stopped (the speech ended): the phrases still waiting for the words
        after them are decided. Returns the cues that play."""
        self._check_open()
        return played(self.session.gestures.end_of_words())

    def heard_time(self, ahead_s: float = 0.0) -> float:
        """Stream time of the audio heard ``ahead_s`` seconds from now (unpaced: the end of the pushed audio)."""
        if not self.paced:
            return self.audio_seconds + ahead_s
        now = self.clock.now()
        return self._timeline.stream_time(now + ahead_s, now)

    def gesture(self, name: str) -> None:
        """Carry out a lexicon gesture (``"wave"``, ``"bow"``…) as soon as the look-ahead allows (thread-safe)."""
        self.control(gesture=name)

    @one_at_a_time
    def flush(self) -> list[PoseFrame]:
        """The frames still owed for the audio pushed so far, without closing: the look-ahead (and smoothing window)
        after it is filled with silence, which becomes part of the stream (about a third of a second: the next block
        follows it, and the silence's own poses come out too); pending speech-act words are decided. For the end of
        an utterance (a TTS reply, a push-to-talk release) when the stream goes on; returns the frames generated."""
        self._check_open()
        self.session.gestures.end_of_words()
        frames = self._generate(self._converter.flush())
        if self._timeline.samples == self._flushed_end:  # no audio since the last flush: nothing is owed
            return frames
        frames += self._generate(np.zeros(self.session.silence_to_flush(), np.float32))
        self._flushed_end = self._timeline.samples
        return frames

    @one_at_a_time
    def close(self) -> list[PoseFrame]:
        """End the stream: the last poses (look-ahead padded with silence), each released on time, then the
        outputs closed; returns the frames generated by the close. A second call returns []."""
        if self._closed:
            return []
        try:
            frames = self._generate(self._converter.flush())
            frames += self._submit(self.session.finish())
            self._release.drain()
        finally:
            self._shut()
        return frames

    @one_at_a_time
    def stop(self) -> None:
        """End now: frames not yet due are dropped, the outputs closed."""
        if not self._closed:
            self._shut()

    def report(self) -> EngineReport:
        """What the stream measured so far (stage timings, rtf, scheduler counters, outputs)."""
        audio = SourceStats(samples=self._timeline.samples)
        report = make_report(self.session, audio, self._release.scheduler.stats.to_dict(), warm_up_s=self.warm_up_s,
                             degradation=self._release.ladder_report())
        report.outputs = self.bridges.counters()
        return report

    def _say(self, text: str, samples: np.ndarray) -> list[PoseFrame]:
        """Cue ``text``'s gestures on ``samples`` (16 kHz, the stream's next audio), then push them."""
        tokens = SENTENCE_TEXT.check("text", text).split()
        if tokens and samples.shape[0] and self.settings.gestures is not None:
            self.session.gestures.hear_sentence_with_audio(" ".join(tokens), samples, self.audio_seconds)
        return self._generate(samples)

    def _generate(self, samples: np.ndarray) -> list[PoseFrame]:
        if not samples.shape[0]:
            return []
        now = self.clock.now() if self.paced else self._timeline.samples / SAMPLE_RATE
        return self._submit(self.session.push(self._timeline.chunk(samples, now)))

    def _submit(self, frames: list[PoseFrame]) -> list[PoseFrame]:
        self._release.submit(frames)
        return frames

    def _send(self, frame: PoseFrame) -> None:
        self.bridges.send(frame)
        self._feeds.put(frame)
        if self._on_frame is not None:
            self._on_frame(frame)

    def _close_at_exit(self) -> None:
        """Python is exiting with the stream open: close it, so that a recording is finished, not lost. A stream on
        another clock than the real one (a test's) is stopped instead: its last frames would wait for a time that no
        longer passes; what was recorded is kept."""
        recording = "" if self.outputs.bvh is None else f" and finishing its recording {self.outputs.bvh}"
        logger.warning("a gesturecast.Stream was still open at exit: closing it%s (call close(), or use `with`)",
                       recording)
        if isinstance(self.clock, MonotonicClock):
            self.close()
        else:
            self.stop()

    def _check_open(self) -> None:
        if self._closed:
            raise UserError("this stream is closed; start a new gesturecast.Stream")

    def _shut(self) -> None:
        self._closed = True
        atexit.unregister(self._close_at_exit)
        try:
            self._release.stop()
            self.session.gestures.stop_worker()
        finally:
            self._feeds.end()
            self.bridges.close()
        if self.bridges.close_errors:
            raise UserError("; ".join(self.bridges.close_errors))

    def __enter__(self) -> Stream:
        return self

    def __exit__(self, error_type: type | None, *exc_info: object) -> None:
        if error_type is None:
            self.close()
        else:
            self.stop()


def spoken_words(text: str, start: float) -> tuple[Word, ...]:
    """The words of ``text`` from stream time ``start`` on, :data:`SPOKEN_WORD_S` each, checked as a words message's
    are (none for blank text)."""
    items = [{"word": token, "start": start + i * SPOKEN_WORD_S, "end": start + (i + 1) * SPOKEN_WORD_S}
             for i, token in enumerate(text.split())]
    return parse_words(items, "spoken words") if items else ()
