"""The pose stream as JSON (``generate --json``), written frame batch by frame batch.

The document is ``{"bones": [...], "fps": 30, "visemes": [...], "face": [...], "frames": [{seq, capture_time, root,
rotations, speaking, visemes, face, gesture}, ...], "gesture_cues": {...}}`` on one line (``gesture``: the lexicon
gesture being carried out, only on frames that have one; ``gesture_cues``: ``generate``'s cues by outcome, on time,
late, blended, merged, dropped, and a line for each one not on time; ``visemes``: the blend-shape names of
``--lipsync`` and each frame's weights in that order; both absent with ``--lipsync off``; ``face``: the same for
the blinks and the emotion presets, absent with ``--face off``; ``speaking``: the voice activity of the
frame's own audio instant, with a 267 ms hangover), the same bytes as ``json.dumps`` of the
whole document, but the frames are never all in memory: each batch is formatted and written as it comes, into a
temporary file that replaces the target on :meth:`PoseJsonWriter.save` (:func:`gesturecast.files.atomic_file`).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import abandon, atomic_file
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

VISEME_DECIMALS = 4  # weights: 1e-4 is below any visible mouth difference
ROTATION_DECIMALS = 7  # quaternion components: far below any visible difference
ITEM_SEPARATOR = ", "  # json.dumps' default, so the streamed document equals the one-shot one


def frame_record(frame: PoseFrame) -> dict:
    """One frame as the JSON object of the ``frames`` list."""
    record = {
        "seq": frame.seq,
        "capture_time": frame.capture_time,
        "root": [float(v) for v in frame.root_position],
        "rotations": np.round(frame.rotations, ROTATION_DECIMALS).tolist(),  # (J, 4) XYZW
        "speaking": frame.speaking,
    }
    if frame.visemes is not None:
        record["visemes"] = np.round(np.asarray(frame.visemes, np.float64), VISEME_DECIMALS).tolist()  # (5,) in [0, 1]
    if frame.face is not None:
        record["face"] = np.round(np.asarray(frame.face, np.float64), VISEME_DECIMALS).tolist()  # (8,) in [0, 1]
    if frame.gesture:
        record["gesture"] = frame.gesture  # the lexicon gesture(s) being carried out
    return record


class PoseJsonWriter:
    """Append frames with :meth:`write`; :meth:`save` finishes the document and replaces the target."""

    def __init__(self, path: str | Path, viseme_names: tuple[str, ...] = (), face_names: tuple[str, ...] = (),
                 closing: Callable[[], dict] | None = None) -> None:
        self.path = Path(path)
        self.closing = closing  # fields added after the frames when saved (the gesture cues' outcomes)
        self._stack = ExitStack()
        self._file = self._stack.enter_context(atomic_file(self.path))
        self._count = 0
        head = {"bones": list(CANONICAL_WITH_HANDS.names), "fps": int(MOTION_FPS)}
        if viseme_names:
            head["visemes"] = list(viseme_names)
        if face_names:
            head["face"] = list(face_names)
        head = json.dumps({**head, "frames": []})
        self._write(head[: -len("]}")])

    @property
    def num_frames(self) -> int:
        """Frames written so far."""
        return self._count

    def _write(self, text: str) -> None:
        try:
            self._file.write(text)
        except OSError as error:
            raise UserError(f"cannot write {self.path}: {error.strerror}") from None

    def write(self, frames: list[PoseFrame]) -> None:
        """Append a batch of frames to the ``frames`` list."""
        for frame in frames:
            self._write((ITEM_SEPARATOR if self._count else "") + json.dumps(frame_record(frame), allow_nan=False))
            self._count += 1

    def save(self) -> None:
        """Close the document (with the ``closing`` fields after the frames); the file replaces the target."""
        extra = self.closing() if self.closing is not None else {}
        self._write("]" + "".join(f", {json.dumps(k)}: {json.dumps(v)}" for k, v in extra.items()) + "}\n")
        self._stack.close()

    def close(self) -> None:
        """Drop an unsaved document (the temporary file is removed, the target left as it was)."""
        abandon(self._stack)

    def __enter__(self) -> PoseJsonWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
