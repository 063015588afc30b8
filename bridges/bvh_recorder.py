"""Streaming BVH recorder for the live engine: frames are written as they arrive.

Frames go to a temporary file next to the target (:func:`gesturecast.files.atomic_file`), which
replaces the target only when the recording is closed (end of input, Ctrl-C): an existing file of
that name is never truncated by a run that fails. A recording closed with no frames (an input that
failed at once, Ctrl-C before the first frame) is dropped: a BVH without frames replaces nothing.
The ``Frames:`` count sits in a fixed-width field
that is rewritten after every frame, so even the temporary file of a killed run is a valid BVH of
the frames written. A write error (disk full, file size limit) stops the recording, leaves the
target as it was, and :meth:`BvhRecorder.close` raises it as one :class:`UserError` line.
The hierarchy and number formatting come from :mod:`gesturecast.models.motion.bvh` /
:mod:`gesturecast.models.motion.canonical_bvh` (the same code as ``motion_to_bvh``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import abandon, atomic_file
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.bvh import format_frame_time, format_hierarchy, format_motion_rows
from gesturecast.models.motion.canonical_bvh import canonical_frame_values, canonical_layout
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

FRAME_COUNT_WIDTH = 12  # digits reserved for the frame count: room for 10^12 frames

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class BvhRecorderConfig:
    skeleton: Skeleton = CANONICAL_WITH_HANDS
    fps: float = MOTION_FPS


class BvhRecorder:
    """Append canonical poses to a BVH file; ``close()`` (or the context manager) finishes it."""

    name = "bvh"

    def __init__(self, path: str | Path, skeleton: Skeleton = CANONICAL_WITH_HANDS, fps: float = MOTION_FPS) -> None:
        self.config = BvhRecorderConfig(skeleton, fps)
        self.path = Path(path)
        self.frames_written = 0
        self.error: str | None = None  # the write error that stopped the recording
        layout = canonical_layout(fps, skeleton)
        self._stack = ExitStack()
        self._file = self._stack.enter_context(atomic_file(self.path))
        self.partial_path = Path(self._file.name)  # the recording so far: a valid BVH after every frame
        try:
            self._write(lambda: self._start(format_hierarchy(layout), format_frame_time(1.0 / fps)))
        except UserError:
            self.close()  # removes the temporary file and raises the error

    def _start(self, hierarchy: str, frame_time: str) -> None:
        self._file.write(hierarchy + "Frames: ")
        self._count_position = self._file.tell()
        self._file.write(self._count_field() + "\n" + frame_time)
        self._file.flush()

    def _count_field(self) -> str:
        return str(self.frames_written).ljust(FRAME_COUNT_WIDTH)

    def send(self, frame: PoseFrame) -> None:
        """Append one pose and update the frame count, so the file is valid after every call."""
        if self.error is not None:
            return
        values = canonical_frame_values(frame.rotations[None], np.asarray(frame.root_position)[None],
                                        self.config.skeleton)  # (1, C)
        self._write(lambda: self._append(format_motion_rows(values)))

    def _append(self, rows: str) -> None:
        self._file.write(rows)
        end = self._file.tell()
        self.frames_written += 1
        self._file.seek(self._count_position)
        self._file.write(self._count_field())
        self._file.seek(end)
        self._file.flush()

    def _write(self, step: Callable[[], None]) -> None:
        """Run one write; an OSError ends the recording (kept in :attr:`error`, raised again by close)."""
        try:
            step()
        except OSError as error:
            self.error = f"cannot record BVH to {self.path}: {error.strerror or error}"
            raise UserError(self.error) from None

    def close(self) -> None:
        """Finish the file: it replaces the target; with no frames it is dropped; after a write error it is
        removed and the error raised."""
        if self.error is None and self.frames_written:
            self._stack.close()
            return
        abandon(self._stack)
        if self.error is not None:
            raise UserError(f"{self.error}; {self.path} was left as it was")
        logger.warning("no frames recorded, so %s was not written (an existing file is left as it was)", self.path)

    def __enter__(self) -> BvhRecorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
