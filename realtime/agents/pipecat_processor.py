"""``GesturecastProcessor``: gestures for a Pipecat voice agent (speech in → LLM → TTS audio out).

Put it in a Pipecat ``Pipeline`` after the TTS service (``audio="output"``: the avatar gestures to
the bot's voice) or after the input transport (``audio="input"``: to the user's voice). It passes
every frame downstream unchanged; on the side it

- converts each audio frame (16-bit PCM, any rate / channel count) to 16 kHz mono
  (:class:`~gesturecast.realtime.audio.pcm.PcmConverter`) and feeds a :class:`GestureSession`
  (on a worker thread, so the event loop never waits on the model);
- times the audio as it will be heard: a block starts when it arrives or when the previous block
  ends, whichever is later (TTS audio arrives faster than it is played, back to back);
- hands the pose frames to the scheduler, which releases each at capture + L to the bridges
  (VMC, OSC, WebSocket, BVH: the ``gesturecast live`` output flags, through ``build_outputs``);
- maps style changes from the pipeline onto the session's controls: a :class:`GestureStyleFrame`
  (in order with the audio), and/or ``style_for_text`` called on each ``TTSTextFrame`` (one style
  per spoken sentence, as GestureDiffuCLIP changes style sentence by sentence).

``EndFrame`` flushes the stream: the last poses are generated and released before the frame goes on,
and the outputs are closed; ``CancelFrame`` stops at once. Install with ``pip install 'gesturecast[pipecat]'``.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from pipecat.frames.frames import (
    CancelFrame,
    DataFrame,
    EndFrame,
    Frame,
    InputAudioRawFrame,
    OutputAudioRawFrame,
    StartFrame,
    TTSTextFrame,
)
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor

from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.errors import UserError
from gesturecast.realtime.audio.files import SAMPLE_RATE
from gesturecast.realtime.audio.pcm import PcmConverter
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.engine import drain
from gesturecast.realtime.engine_setup import (
    add_generation_arguments,
    add_output_arguments,
    build_outputs,
    build_session,
)
from gesturecast.realtime.session import GestureSession
from gesturecast.realtime.timing.clock import Clock, MonotonicClock
from gesturecast.realtime.timing.scheduler import FrameScheduler, SchedulerConfig, SchedulerWorker

logger = logging.getLogger(__name__)

AUDIO_OUTPUT = "output"  # the bot's voice: OutputAudioRawFrame (TTSAudioRawFrame, …)
AUDIO_INPUT = "input"  # the user's voice: InputAudioRawFrame
AUDIO_FRAME_TYPES = {AUDIO_OUTPUT: OutputAudioRawFrame, AUDIO_INPUT: InputAudioRawFrame}

StyleForText = Callable[[str], "dict | None"]  # spoken text → a control message (e.g. {"style": "happy"}) or None


@dataclass
class GestureStyleFrame(DataFrame):
    """A style change for the avatar, in order with the audio around it.

    ``control`` holds the keys of a session control message: style, prompt, style2, part_styles, gamma, guidance,
    audio_guidance, root (the same as the WebSocket control messages, docs/bridges.md)."""

    control: dict = field(default_factory=dict)


class AudioTimeline:
    """Stream sample indices and capture times of audio that is played back to back."""

    def __init__(self) -> None:
        self.samples = 0
        self._end_time = float("-inf")

    def chunk(self, samples: np.ndarray, now: float) -> AudioChunk:
        """The chunk of (n,) samples arriving at ``now``: it starts now, or where the previous one ends."""
        start_time = max(now, self._end_time)
        chunk = AudioChunk(samples, self.samples, start_time)
        self.samples += samples.shape[0]
        self._end_time = start_time + samples.shape[0] / SAMPLE_RATE
        return chunk


class _FlagParser(argparse.ArgumentParser):
    """The ``live`` flags for a library call: a bad flag is a UserError, not a process exit."""

    def error(self, message: str) -> None:  # type: ignore[override]  # argparse's contract: never returns
        raise UserError(message)


def parse_flags(flags: list[str]) -> argparse.Namespace:
    """``gesturecast live``'s generation and output flags (``--style``, ``--vmc``, ``--bvh``, …)."""
    parser = _FlagParser(prog="GesturecastProcessor")
    add_generation_arguments(parser)
    add_output_arguments(parser)
    return parser.parse_args(flags)


class GesturecastProcessor(FrameProcessor):
    """A Pipecat FrameProcessor that drives an avatar from the pipeline's audio (see the module docstring)."""

    def __init__(self, session: GestureSession, outputs: BridgeFanout, *, clock: Clock | None = None,
                 scheduler_config: SchedulerConfig | None = None, audio: str = AUDIO_OUTPUT,
                 style_for_text: StyleForText | None = None, **kwargs) -> None:
        super().__init__(**kwargs)
        if audio not in AUDIO_FRAME_TYPES:
            raise UserError(f"audio must be one of {', '.join(AUDIO_FRAME_TYPES)}, got {audio!r}")
        self.session = session
        self.outputs = outputs
        self.clock = clock or MonotonicClock()
        self.scheduler = FrameScheduler(self.clock, outputs.send, scheduler_config, stats=session.stats)
        self._audio_type = AUDIO_FRAME_TYPES[audio]
        self._style_for_text = style_for_text
        self._converter = PcmConverter()
        self._timeline = AudioTimeline()
        self._worker: SchedulerWorker | None = None

    @property
    def audio_seconds(self) -> float:
        """Seconds of audio fed to the session so far."""
        return self._timeline.samples / SAMPLE_RATE

    @classmethod
    def from_flags(cls, flags: list[str], **kwargs) -> GesturecastProcessor:
        """A processor configured like ``gesturecast live`` (e.g. ``["--vmc", "127.0.0.1:39539", "--style",
        "happy"]``); ``kwargs`` go to the constructor (``audio``, ``style_for_text``, ``name``)."""
        args = parse_flags(flags)
        clock = MonotonicClock()
        session = build_session(args, clock)
        outputs = build_outputs(args, session, clock)
        return cls(session, outputs, clock=clock, scheduler_config=SchedulerConfig(output_fps=float(args.fps)),
                   **kwargs)

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if isinstance(frame, StartFrame):
            self._start()
        elif isinstance(frame, self._audio_type):
            await self._feed(self._converter.convert(frame.audio, frame.sample_rate, frame.num_channels))
        elif isinstance(frame, GestureStyleFrame):
            self._submit(frame.control)
        elif isinstance(frame, TTSTextFrame) and self._style_for_text is not None:
            control = self._style_for_text(frame.text)
            if control:
                self._submit(control)
        elif isinstance(frame, EndFrame):
            await self._finish()
        elif isinstance(frame, CancelFrame):
            self._stop()
        await self.push_frame(frame, direction)

    def _start(self) -> None:
        if self._worker is None:
            self._worker = SchedulerWorker(self.scheduler)
            self._worker.start()

    def _submit(self, control: dict) -> None:
        """A style change from the pipeline; one the model cannot use is logged and the stream goes on."""
        try:
            self.session.controls.submit(control)
        except UserError as error:
            logger.warning("style change %s ignored: %s", control, error)

    async def _feed(self, samples: np.ndarray) -> None:
        """(n,) 16 kHz samples → poses, generated off the event loop, queued for release at capture + L."""
        if not samples.shape[0] or self._worker is None:
            return
        chunk = self._timeline.chunk(samples, self.clock.now())
        self._worker.submit(await asyncio.to_thread(self.session.push, chunk))

    async def _finish(self) -> None:
        """End of stream: the rest of the audio, the look-ahead's poses, all released on time, outputs closed."""
        if self._worker is None:
            return
        await self._feed(self._converter.flush())
        self._worker.submit(await asyncio.to_thread(self.session.finish))
        await asyncio.to_thread(drain, self._worker)
        self._stop()

    def _stop(self) -> None:
        """Stop releasing frames and close the outputs (a BVH recorder writes its file here)."""
        if self._worker is not None:
            self._worker.stop()
            self._worker = None
            self.outputs.close()
