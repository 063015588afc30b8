"""What the Pipecat tests share: the offline example's ``run_pipeline`` (a pipeline run to its end), a recorder of
what reaches the next stage, and a stage that holds one kind of frame back for a while (a service that reports text
late)."""

from __future__ import annotations

import asyncio
import importlib.util
from pathlib import Path

from pipecat.frames.frames import Frame
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "pipecat_offline.py"


def load_example():
    """examples/pipecat_offline.py as a module (its ``run_pipeline`` runs the tests' pipelines too)."""
    spec = importlib.util.spec_from_file_location("pipecat_offline", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


run_pipeline = load_example().run_pipeline


class Recorder(FrameProcessor):
    """The next stage of the pipeline: keeps every frame that reaches it."""

    def __init__(self) -> None:
        super().__init__()
        self.frames: list[Frame] = []

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        self.frames.append(frame)
        await self.push_frame(frame, direction)


class Late(FrameProcessor):
    """Passes every frame on; a frame of ``frame_type`` only after ``seconds`` (the frames after it wait too)."""

    def __init__(self, frame_type: type, seconds: float) -> None:
        super().__init__()
        self.frame_type = frame_type
        self.seconds = seconds

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if isinstance(frame, self.frame_type):
            await asyncio.sleep(self.seconds)
        await self.push_frame(frame, direction)
