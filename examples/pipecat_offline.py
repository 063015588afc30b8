"""A Pipecat pipeline with gesturecast in it, offline: a WAV file stands in for the TTS service.

    pip install 'gesturecast[pipecat]'
    python examples/pipecat_offline.py SPEECH.wav --vmc 127.0.0.1:39539 --bvh take.bvh --styles neutral,old

The file's audio is cut into 20 ms ``OutputAudioRawFrame`` s (what a TTS service pushes, faster than it
is played) and queued into ``Pipeline([GesturecastProcessor])``; with ``--styles A,B,…`` the file is
split into that many equal "sentences" and a ``GestureStyleFrame`` before each one sets its style.
Poses go out at capture + L to the outputs (``gesturecast.Outputs``: VMC, BVH here);
the run ends when the last pose has been released.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
from pathlib import Path

import loguru
import numpy as np
import soundfile
from pipecat.frames.frames import EndFrame, Frame, OutputAudioRawFrame
from pipecat.pipeline.pipeline import Pipeline
from pipecat.pipeline.worker import PipelineWorker
from pipecat.processors.frame_processor import FrameProcessor
from pipecat.workers.runner import WorkerRunner

import gesturecast
from gesturecast.realtime.agents.pipecat_processor import GesturecastProcessor, GestureStyleFrame
from gesturecast.realtime.audio.pcm import PCM16_FULL_SCALE

FRAME_S = 0.02  # audio per frame, as TTS services and transports chunk it
PCM16_MAX = 32767
START_TIMEOUT_S = 60.0  # pipeline start on a loaded machine


def audio_frames(path: Path, styles: list[str]) -> list[Frame]:
    """The file as 16-bit PCM frames at its own rate and channel count, a style frame before each 'sentence'."""
    samples, rate = soundfile.read(str(path), dtype="float32", always_2d=True)  # (n, C)
    pcm = np.clip(np.round(samples * PCM16_FULL_SCALE), -PCM16_MAX - 1, PCM16_MAX).astype("<i2")  # (n, C)
    step = max(1, round(FRAME_S * rate))
    starts = range(0, pcm.shape[0], step)
    sentence = -(-len(starts) // max(1, len(styles)))  # frames per sentence (ceiling)
    frames: list[Frame] = []
    for index, start in enumerate(starts):
        if styles and index % sentence == 0:
            frames.append(GestureStyleFrame(control={"style": styles[index // sentence]}))
        frames.append(OutputAudioRawFrame(audio=pcm[start : start + step].tobytes(), sample_rate=rate,
                                          num_channels=pcm.shape[1]))
    return frames


async def run_pipeline(processors: list[FrameProcessor], frames: list[Frame]) -> None:
    """``frames`` then an EndFrame through ``Pipeline(processors)``; returns when the pipeline has ended."""
    worker = PipelineWorker(Pipeline(processors), cancel_on_idle_timeout=False, enable_rtvi=False)
    started = asyncio.Event()

    @worker.event_handler("on_pipeline_started")
    async def on_started(_worker, _frame):
        started.set()

    async def feed() -> None:
        await asyncio.wait_for(started.wait(), START_TIMEOUT_S)
        await worker.queue_frames([*frames, EndFrame()])

    runner = WorkerRunner(handle_sigint=False)
    await runner.add_workers(worker)
    await asyncio.gather(runner.run(), feed())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("audio", type=Path, help="speech file standing in for the TTS output")
    parser.add_argument("--styles", default="", help="comma-separated styles, one per equal part of the file")
    parser.add_argument("--model", type=Path, help="model bundle folder (default: the bundled one)")
    parser.add_argument("--vmc", metavar="HOST[:PORT]", help="VMC receiver")
    parser.add_argument("--bvh", type=Path, help="record the poses as BVH")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    loguru.logger.remove()  # Pipecat logs with loguru, at DEBUG by default: keep its warnings only
    loguru.logger.add(sys.stderr, level="WARNING")
    styles = [s for s in args.styles.split(",") if s]
    settings = gesturecast.Settings() if args.model is None else gesturecast.Settings(model=args.model)
    processor = GesturecastProcessor(settings, gesturecast.Outputs(vmc=args.vmc, bvh=args.bvh))
    asyncio.run(run_pipeline([processor], audio_frames(args.audio, styles)))
    logging.info("%d poses from %.2f s of audio; style at the end: %s", processor.session.frames_out,
                 processor.audio_seconds, processor.session.controls.describe())
    return 0


if __name__ == "__main__":
    sys.exit(main())
