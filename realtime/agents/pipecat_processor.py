"""``GesturecastProcessor``: gestures for a Pipecat voice agent (speech in → LLM → TTS audio out).

Put it in a Pipecat ``Pipeline`` after the TTS service (``audio="output"``: the avatar gestures to
the bot's voice) or after the input transport (``audio="input"``: to the user's voice). It passes
every frame downstream unchanged; on the side it drives a :class:`gesturecast.Stream` (built from a
:class:`Settings` and :class:`Outputs`, the library's own types):

- each audio frame (16-bit PCM, any rate / channel count) is pushed to the stream (which converts it to 16 kHz
  mono) on a worker thread, so the event loop never waits on the model; the stream times the audio as it will be
  heard (a block starts when it arrives or when the previous block ends, whichever is later: TTS audio arrives
  faster than it is played, back to back) and releases each pose at capture + L to the outputs;
- the words the TTS speaks (``TTSTextFrame``) cue the lexicon's gestures: a trigger phrase ("hello", "thank you")
  makes its gesture with the stroke on the word; a frame with a presentation time (TTS services with word
  timestamps stamp each word) is placed at that time, one without at the audio being heard (``gestures=True``);
- style changes from the pipeline become the stream's controls: a :class:`GestureStyleFrame` (in order with the
  audio), and/or ``style_for_text`` called on each ``TTSTextFrame`` (one style per spoken sentence, as
  GestureDiffuCLIP changes style sentence by sentence).

``EndFrame`` closes the stream: the last poses are generated and released before the frame goes on, and the
outputs are closed; ``CancelFrame`` stops at once. Install with ``pip install 'gesturecast[pipecat]'``.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from pipecat.frames.frames import (
    CancelFrame,
    DataFrame,
    EndFrame,
    Frame,
    InputAudioRawFrame,
    OutputAudioRawFrame,
    TTSTextFrame,
)
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor

from gesturecast.bridges.output_settings import Outputs
from gesturecast.errors import UserError
from gesturecast.realtime.run.stream import Stream
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

AUDIO_OUTPUT = "output"  # the bot's voice: OutputAudioRawFrame (TTSAudioRawFrame, …)
AUDIO_INPUT = "input"  # the user's voice: InputAudioRawFrame
AUDIO_FRAME_TYPES = {AUDIO_OUTPUT: OutputAudioRawFrame, AUDIO_INPUT: InputAudioRawFrame}

StyleForText = Callable[[str], "dict | None"]  # spoken text → a control message (e.g. {"style": "happy"}) or None


@dataclass
class GestureStyleFrame(DataFrame):
    """A style change for the avatar, in order with the audio around it.

    ``control`` holds the keys of a session control message: style, prompt, style2, part_styles, gamma,
    style_strength, guidance, audio_guidance, root (the same as the WebSocket control messages, docs/bridges.md)."""

    control: dict = field(default_factory=dict)


class GesturecastProcessor(FrameProcessor):
    """A Pipecat FrameProcessor that drives an avatar from the pipeline's audio (see the module docstring).

    settings, outputs: as for :class:`gesturecast.Stream` (e.g. ``Settings(style="happy")``,
    ``Outputs(vmc="127.0.0.1")``); ``stream``: a stream built by the caller instead. ``kwargs`` go to Pipecat's
    FrameProcessor (``name``)."""

    def __init__(self, settings: Settings | None = None, outputs: Outputs | None = None, *,
                 stream: Stream | None = None, audio: str = AUDIO_OUTPUT,
                 style_for_text: StyleForText | None = None, gestures: bool = True, **kwargs) -> None:
        super().__init__(**kwargs)
        if audio not in AUDIO_FRAME_TYPES:
            raise UserError(f"audio must be one of {', '.join(AUDIO_FRAME_TYPES)}, got {audio!r}")
        self.stream = stream or Stream(settings, outputs)
        self.session = self.stream.session
        self._audio_type = AUDIO_FRAME_TYPES[audio]
        self._style_for_text = style_for_text
        self._gestures = gestures and self.stream.settings.gestures is not None

    @property
    def audio_seconds(self) -> float:
        """Seconds of audio fed to the stream so far."""
        return self.stream.audio_seconds

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if isinstance(frame, self._audio_type):
            await asyncio.to_thread(self.stream.push_pcm16, frame.audio, frame.sample_rate, frame.num_channels)
        elif isinstance(frame, GestureStyleFrame):
            self._submit(frame.control)
        elif isinstance(frame, TTSTextFrame):
            self._spoken(frame)
        elif isinstance(frame, EndFrame):
            await self._finish()
        elif isinstance(frame, CancelFrame):
            self.stream.stop()
        await self.push_frame(frame, direction)

    def _spoken(self, frame: TTSTextFrame) -> None:
        """Text the TTS speaks: its style (``style_for_text``) and the gestures of its trigger words."""
        if self._style_for_text is not None and (control := self._style_for_text(frame.text)):
            self._submit(control)
        if self._gestures:
            ahead_s = 0.0 if frame.pts is None else (frame.pts - self.get_clock().get_time()) / 1e9
            self.stream.spoken(frame.text, self.stream.heard_time(ahead_s))

    def _submit(self, control: dict) -> None:
        """A style change from the pipeline; one the model cannot use is logged and the stream goes on."""
        try:
            self.stream.control(control)
        except UserError as error:
            logger.warning("style change %s ignored: %s", control, error)

    async def _finish(self) -> None:
        """End of stream: the rest of the audio, the look-ahead's poses, all released on time, outputs closed."""
        await asyncio.to_thread(self.stream.close)
