"""``GesturecastProcessor``: gestures for a Pipecat voice agent (speech in → LLM → TTS audio out).

Put it in a Pipecat ``Pipeline`` after the TTS service (``audio="output"``: the avatar gestures to
the bot's voice) or after the input transport (``audio="input"``: to the user's voice). It passes
every frame downstream unchanged; on the side it drives a :class:`gesturecast.Stream` (built from a
:class:`Settings` and :class:`Outputs`, the library's own types):

- each audio frame (16-bit PCM, any rate / channel count) is pushed to the stream (which converts it to 16 kHz
  mono) on a worker thread, so the event loop never waits on the model; the stream times the audio as it will be
  heard (a block starts when it arrives or when the previous block ends, whichever is later: TTS audio arrives
  faster than it is played, back to back) and releases each pose at capture + L to the outputs;
- the words the TTS speaks (``TTSTextFrame``) cue the lexicon's gestures: a speech act ("hello", "thank you",
  docs/gestures.md) makes its gesture with the stroke on the word; a frame with a presentation time (TTS services
  with word timestamps stamp each word) is placed at that time, a word frame without one where the audio received
  with it ends, a sentence at the audio being heard (``gestures=True``); ``TTSStoppedFrame`` decides the phrases
  still waiting for words after them;
- ``hold_s`` (0 to :data:`MAX_HOLD_S`): audio, word and style frames are held back by that many seconds of audio
  before they go to the stream and downstream, in order, so words that come *with* their audio are known before
  their latents are generated and the stroke lands on the word (:data:`SUGGESTED_HOLD_S`); the voice is delayed by
  the same amount. Cues too late for their word are logged and counted by the stream's cue plan;
- style changes from the pipeline become the stream's controls: a :class:`GestureStyleFrame` (in order with the
  audio), and/or ``style_for_text`` called on each ``TTSTextFrame`` (one style per spoken sentence, as
  GestureDiffuCLIP changes style sentence by sentence).

``EndFrame`` closes the stream: the last poses are generated and released before the frame goes on, and the
outputs are closed; ``CancelFrame`` stops at once. Install with ``pip install 'gesturecast[pipecat]'``.
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from pipecat.frames.frames import (
    CancelFrame,
    DataFrame,
    EndFrame,
    Frame,
    InputAudioRawFrame,
    OutputAudioRawFrame,
    TranscriptionFrame,
    TTSStoppedFrame,
    TTSTextFrame,
    VADUserStartedSpeakingFrame,
)
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor

from gesturecast.bridges.output_settings import Outputs
from gesturecast.errors import UserError
from gesturecast.realtime.agents.sentence_hold import MAX_SENTENCE_HOLD_S, WORDS, SentenceHold
from gesturecast.realtime.run.stream import Stream
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

AUDIO_OUTPUT = "output"  # the bot's voice: OutputAudioRawFrame (TTSAudioRawFrame, …)
AUDIO_INPUT = "input"  # the user's voice: InputAudioRawFrame
AUDIO_FRAME_TYPES = {AUDIO_OUTPUT: OutputAudioRawFrame, AUDIO_INPUT: InputAudioRawFrame}
MAX_HOLD_S = 2.0  # the most audio the processor may hold back (hold_s)
SUGGESTED_HOLD_S = 1.2  # a word frame that comes with its audio: the 3 words a decision may wait for, the approach
USER_ONSET_LEAD_S = 0.3  # a user's speech starts up to this long before the VAD's start_secs say

StyleForText = Callable[[str], "dict | None"]  # spoken text → a control message (e.g. {"style": "happy"}) or None


@dataclass
class GestureStyleFrame(DataFrame):
    """A style change for the avatar, in order with the audio around it.

    ``control`` holds the keys of a session control message: style, prompt, style2, part_styles, gamma,
    style_strength, guidance, audio_guidance, root, intensity, pause (the same as the WebSocket control messages,
    docs/bridges.md)."""

    control: dict = field(default_factory=dict)


class GesturecastProcessor(FrameProcessor):
    """A Pipecat FrameProcessor that drives an avatar from the pipeline's audio (see the module docstring).

    settings, outputs: as for :class:`gesturecast.Stream` (e.g. ``Settings(style="happy")``,
    ``Outputs(vmc="127.0.0.1")``); ``stream``: a stream built by the caller instead. ``kwargs`` go to Pipecat's
    FrameProcessor (``name``)."""

    def __init__(self, settings: Settings | None = None, outputs: Outputs | None = None, *,
                 stream: Stream | None = None, audio: str = AUDIO_OUTPUT,
                 style_for_text: StyleForText | None = None, gestures: bool = True, hold_s: float = 0.0,
                 sentence_hold_s: float = MAX_SENTENCE_HOLD_S, **kwargs) -> None:
        super().__init__(**kwargs)
        if audio not in AUDIO_FRAME_TYPES:
            raise UserError(f"audio must be one of {', '.join(AUDIO_FRAME_TYPES)}, got {audio!r}")
        if not 0.0 <= hold_s <= MAX_HOLD_S:
            raise UserError(f"hold_s must be between 0 and {MAX_HOLD_S} s, got {hold_s}")
        if not 0.0 <= sentence_hold_s <= MAX_SENTENCE_HOLD_S:
            raise UserError(f"sentence_hold_s must be between 0 and {MAX_SENTENCE_HOLD_S} s, got {sentence_hold_s}")
        self.hold_s = hold_s
        self._held: deque[tuple[Frame, FrameDirection]] = deque()  # audio, words and styles not yet passed on
        self._held_s = 0.0  # seconds of audio in it
        self.stream = stream or Stream(settings, outputs)
        self.session = self.stream.session
        self._audio_type = AUDIO_FRAME_TYPES[audio]
        self._style_for_text = style_for_text
        self._gestures = gestures and self.stream.settings.gestures is not None
        self._sentences = (SentenceHold(self.stream, self._audio_type, self._release, self.push_frame, sentence_hold_s)
                           if self._gestures and audio == AUDIO_OUTPUT and sentence_hold_s > 0 else None)
        self._user_speech_s: float | None = None  # stream time the user's current utterance began (VAD)

    @property
    def audio_seconds(self) -> float:
        """Seconds of audio fed to the stream so far."""
        return self.stream.audio_seconds

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if self._sentences is not None and await self._sentences.take(frame, direction):
            return  # held with its sentence
        if isinstance(frame, TTSTextFrame) and self._gestures:
            self._cue_words(frame)  # on arrival: with a hold, its audio is not in the stream yet
        elif isinstance(frame, VADUserStartedSpeakingFrame):
            self._user_speech_s = max(0.0, self.stream.audio_seconds - frame.start_secs - USER_ONSET_LEAD_S)
        elif isinstance(frame, TranscriptionFrame) and self._gestures and self._audio_type is InputAudioRawFrame:
            await self._cue_transcription(frame)
        if self._word_hold and isinstance(frame, (self._audio_type, TTSTextFrame, GestureStyleFrame)):
            self._held.append((frame, direction))
            self._held_s += self._duration(frame)
            while self._held and self._held_s > self.hold_s:
                await self._release_held()
            return
        if isinstance(frame, CancelFrame):
            self._held.clear()  # cancelled: nothing more is played
            self._held_s = 0.0
        while self._held:  # any other frame: what is held goes on first, in order
            await self._release_held()
        await self._release(frame, direction)

    @property
    def _word_hold(self) -> bool:
        """``hold_s`` holds frames: set, and the utterance reports words (the sentence hold has none of its frames)."""
        return self.hold_s > 0 and (self._sentences is None or self._sentences.order == WORDS)

    async def _release_held(self) -> None:
        """The oldest frame held by ``hold_s`` goes on."""
        frame, direction = self._held.popleft()
        self._held_s -= self._duration(frame)
        await self._release(frame, direction)

    async def _release(self, frame: Frame, direction: FrameDirection) -> None:
        """Act on ``frame`` and pass it on."""
        if isinstance(frame, self._audio_type):
            await asyncio.to_thread(self.stream.push_pcm16, frame.audio, frame.sample_rate, frame.num_channels)
        elif isinstance(frame, GestureStyleFrame):
            self._submit(frame.control)
        elif isinstance(frame, TTSTextFrame):
            self._style_of(frame)
        elif isinstance(frame, TTSStoppedFrame) and self._gestures:
            self.stream.end_of_words()  # the utterance ended: its last phrases need no more words
        elif isinstance(frame, EndFrame):
            await self._finish()
        elif isinstance(frame, CancelFrame):
            self.stream.stop()
        await self.push_frame(frame, direction)

    def _duration(self, frame: Frame) -> float:
        """Seconds of audio in ``frame`` (0 for any other frame)."""
        if not isinstance(frame, self._audio_type):
            return 0.0
        return len(frame.audio) / (2 * frame.num_channels * frame.sample_rate)

    def _style_of(self, frame: TTSTextFrame) -> None:
        """The style of the text the TTS speaks (``style_for_text``), in order with its audio."""
        if self._style_for_text is not None and (control := self._style_for_text(frame.text)):
            self._submit(control)

    def _cue_words(self, frame: TTSTextFrame) -> None:
        """The gestures of the words the TTS speaks. A frame with a presentation time is placed there (plus the
        hold); a word frame without one belongs to the audio received with it (it starts where that audio ends); a
        sentence that the sentence hold did not take (``sentence_hold_s=0``) is aligned on the audio heard since the
        sentence before it. Words too late for their stroke are dropped with a log line by the cue plan, and
        counted."""
        if frame.pts is not None:
            start = self.stream.heard_time((frame.pts - self.get_clock().get_time()) / 1e9 + self.hold_s)
        elif frame.text_type == "word":
            start = self.stream.audio_seconds + self._held_s
        else:
            start = None
        try:
            self.stream.spoken(frame.text, start)
        except UserError as error:  # a word the words check refuses (e.g. longer than a word can be): no cue
            logger.warning("words %r not cued: %s", frame.text[:80], error)

    async def _cue_transcription(self, frame: TranscriptionFrame) -> None:
        """The user's own words (``audio="input"``): the STT's final text, aligned on the user's speech heard since
        the VAD said the utterance began (else since the text before it), up to now. It comes after the speech, so
        its cues play late or are dropped with a log line, and are counted."""
        start, self._user_speech_s = self._user_speech_s, None
        try:
            await asyncio.to_thread(self.stream.spoken, frame.text, start, self.stream.audio_seconds)
        except UserError as error:
            logger.warning("transcription %r not cued: %s", frame.text[:80], error)

    def _submit(self, control: dict) -> None:
        """A style change from the pipeline; one the model cannot use is logged and the stream goes on."""
        try:
            self.stream.control(control)
        except UserError as error:
            logger.warning("style change %s ignored: %s", control, error)

    async def _finish(self) -> None:
        """End of stream: the rest of the audio, the look-ahead's poses, all released on time, outputs closed."""
        await asyncio.to_thread(self.stream.close)
