"""Streaming BVH recorder for the live engine: frames are written as they arrive.

The ``Frames:`` count sits in a fixed-width field that is rewritten after every frame, so a
recording that is interrupted (crash, Ctrl-C) still leaves a valid BVH of the frames written.
The hierarchy and number formatting come from :mod:`gesturecast.models.motion.bvh` /
:mod:`gesturecast.models.motion.canonical_bvh` (the same code as ``motion_to_bvh``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import format_frame_time, format_hierarchy, format_motion_rows
from gesturecast.models.motion.canonical_bvh import canonical_bvh_data, canonical_frame_values
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton
from gesturecast.realtime.timing.frames import PoseFrame

FRAME_COUNT_WIDTH = 12  # digits reserved for the frame count: room for 10^12 frames


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
        layout = canonical_bvh_data(np.zeros((0, skeleton.num_joints, 4)), np.zeros((0, 3)), fps, skeleton)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = self.path.open("w", encoding="utf-8", newline="\n")
        except OSError as error:
            raise UserError(f"cannot record BVH to {self.path}: {error.strerror}") from None
        self._file.write(format_hierarchy(layout) + "Frames: ")
        self._count_position = self._file.tell()
        self._file.write(self._count_field() + "\n" + format_frame_time(1.0 / fps))
        self._file.flush()

    def _count_field(self) -> str:
        return str(self.frames_written).ljust(FRAME_COUNT_WIDTH)

    def send(self, frame: PoseFrame) -> None:
        """Append one pose and update the frame count, so the file is valid after every call."""
        values = canonical_frame_values(frame.rotations[None], np.asarray(frame.root_position)[None],
                                        self.config.skeleton)  # (1, C)
        self._file.write(format_motion_rows(values))
        end = self._file.tell()
        self.frames_written += 1
        self._file.seek(self._count_position)
        self._file.write(self._count_field())
        self._file.seek(end)
        self._file.flush()

    def close(self) -> None:
        if not self._file.closed:
            self._file.close()

    def __enter__(self) -> BvhRecorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
