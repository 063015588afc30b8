"""A TTS service's sentences and their audio brought together before the audio reaches the stream.

Many TTS services report a sentence's text, not its words' times: Pipecat 1.14's services without word timestamps
queue the text *after* the sentence's audio; others send it before. For the gestures of a sentence to land on its
words, its words must be known before its latents are generated, so :class:`SentenceHold` holds a sentence's audio
(and the frames between) until the frame that closes it, then gives text and audio to the stream together
(:meth:`gesturecast.Stream.say_pcm16`: the words are placed on that audio and cued, then the audio is pushed)
and passes the held frames on, in order.

- **Which audio is whose.** Within an utterance (``TTSStartedFrame`` … ``TTSStoppedFrame``), the first frame tells
  the order: audio first, each sentence's text closes the audio before it; text first, each sentence's text opens the
  audio after it, closed by the next text or the utterance's end.
- **A bound.** A TTS service synthesises faster than real time, so holding a sentence until its text costs about its
  synthesis time. The hold never lasts more than ``max_hold_s`` of wall time: then the held frames go on, and the text,
  when it comes, is aligned on the audio already heard (:meth:`gesturecast.Stream.spoken` with the audio's span); its
  cues play late or are dropped with a log line, and counted.
- An interruption or a cancel drops what is held (the voice stops); the end passes the held frames on first; other
  system frames (out of band in Pipecat) pass straight on.
- Word frames (``text_type="word"``, or any frame with a presentation time) end the hold for the utterance: their
  times come with them.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field

from pipecat.frames.frames import (
    CancelFrame,
    EndFrame,
    Frame,
    InterruptionFrame,
    SystemFrame,
    TTSStartedFrame,
    TTSStoppedFrame,
    TTSTextFrame,
)
from pipecat.processors.frame_processor import FrameDirection

from gesturecast.realtime.run.stream import Stream

AFTER, BEFORE, WORDS = "after", "before", "words"  # how an utterance reports its text (module docstring)
MAX_SENTENCE_HOLD_S = 2.0  # the longest wall time a sentence's audio waits for its text
FrameAction = Callable[[Frame, FrameDirection], Awaitable[None]]


@dataclass
class HeldSentence:
    """One sentence's frames held back, in order, and its text once known."""

    frames: list[tuple[Frame, FrameDirection]] = field(default_factory=list)
    text: str | None = None
    start_s: float | None = None  # stream time its audio starts at
    passing: bool = False  # the bound passed: its frames go on as they come, its text is aligned on what was heard


class SentenceHold:
    """Holds each sentence's audio until its text is known (module docstring). ``release`` acts on a frame as the
    processor does when nothing is held (audio pushed to the stream, styles submitted) and passes it on;
    ``pass_on`` only passes it on."""

    def __init__(self, stream: Stream, audio_type: type, release: FrameAction, pass_on: FrameAction,
                 max_hold_s: float = MAX_SENTENCE_HOLD_S) -> None:
        self.stream = stream
        self.audio_type = audio_type
        self.release = release
        self.pass_on = pass_on
        self.max_hold_s = max_hold_s
        self.order: str | None = None  # the utterance's order, once its first frame tells
        self.sentence = HeldSentence()
        self._timer: asyncio.Task | None = None

    async def take(self, frame: Frame, direction: FrameDirection) -> bool:
        """Hold ``frame`` or act on it; False when it is not the hold's (the processor handles it)."""
        if isinstance(frame, (CancelFrame, InterruptionFrame)):  # nothing held is played any more
            self._stop_timer()
            self.sentence, self.order = HeldSentence(), None
            return False
        if isinstance(frame, SystemFrame):  # out of band (the user's audio, metrics): never held
            return False
        if isinstance(frame, EndFrame):
            await self.close()
            return False
        if isinstance(frame, (TTSStartedFrame, TTSStoppedFrame)):
            await self.close()
            self.order = None if isinstance(frame, TTSStartedFrame) else self.order
            return False
        if isinstance(frame, TTSTextFrame):
            return await self._text(frame, direction)
        is_audio = isinstance(frame, self.audio_type)
        if self.order == WORDS or self.sentence.passing or not (is_audio or self.sentence.frames):
            if is_audio and self.sentence.start_s is None:
                self.sentence.start_s = self.stream.audio_seconds
            return False
        self._hold(frame, direction)
        return True

    async def close(self) -> None:
        """The sentence is complete: text and audio to the stream together, or its text aligned on what was heard
        when its audio went on without it; its frames go on in order."""
        sentence, self.sentence = self.sentence, HeldSentence()
        self._stop_timer()
        audio = [frame for frame, _ in sentence.frames if isinstance(frame, self.audio_type)]
        if sentence.text is not None and audio and len({(f.sample_rate, f.num_channels) for f in audio}) == 1:
            return await self._say(sentence, audio)
        for frame, direction in sentence.frames:
            await self.release(frame, direction)
        if sentence.text is not None and not (sentence.passing and self.order == BEFORE):  # (aligned at the bound)
            start = self.stream.audio_seconds if sentence.start_s is None else sentence.start_s
            await asyncio.to_thread(self.stream.spoken, sentence.text, start, self.stream.audio_seconds)

    async def _text(self, frame: TTSTextFrame, direction: FrameDirection) -> bool:
        if frame.pts is not None or frame.text_type == "word":
            await self.close()
            self.order = WORDS
            return False
        if self.order is None:
            self.order = AFTER if self.sentence.start_s is not None else BEFORE
        if self.order == BEFORE:
            await self.close()  # this text closes the sentence before it and opens its own
        self.sentence.text = frame.text
        self._hold(frame, direction)
        if self.order == AFTER:
            await self.close()
        return True

    def _hold(self, frame: Frame, direction: FrameDirection) -> None:
        self.sentence.frames.append((frame, direction))
        if isinstance(frame, self.audio_type) and self.sentence.start_s is None:
            self.sentence.start_s = self.stream.audio_seconds
            self._timer = asyncio.create_task(self._bound())

    async def _bound(self) -> None:
        """The wall-time bound passed: the held frames go on without their text, and the rest of the sentence's as
        they come; a text that came first is aligned on its audio as that arrives."""
        await asyncio.sleep(self.max_hold_s)
        self._timer = None
        sentence = self.sentence
        sentence.passing = True
        held, sentence.frames = sentence.frames, []
        for frame, direction in held:
            await self.release(frame, direction)
        if sentence.text is not None and self.order == BEFORE:
            await asyncio.to_thread(self.stream.spoken, sentence.text, sentence.start_s)

    def _stop_timer(self) -> None:
        if self._timer is not None and self._timer is not asyncio.current_task():
            self._timer.cancel()
        self._timer = None

    async def _say(self, sentence: HeldSentence, audio: list[Frame]) -> None:
        """Text and audio to the stream together, then the held frames on in order (the audio already pushed)."""
        said = False
        for frame, direction in sentence.frames:
            if not isinstance(frame, self.audio_type):
                await self.release(frame, direction)
            elif said:
                await self.pass_on(frame, direction)
            else:
                data = b"".join(f.audio for f in audio)
                await asyncio.to_thread(self.stream.say_pcm16, sentence.text, data, frame.sample_rate,
                                        frame.num_channels)
                await self.pass_on(frame, direction)
                said = True
