"""One audio file → a BVH or a VRM Animation (and optionally the pose stream as JSON, a .vrma beside the BVH):
the per-file work of ``generate``.

``gesturecast generate FILE`` and every worker of ``generate --batch`` call :func:`generate_to_files`,
so a batch writes exactly the bytes the single-file command writes. The session is fed by the unpaced
file source (:func:`gesturecast.realtime.run.engine.offline_batches`), frames are streamed into the
atomic writers (constant memory on any duration), and the outputs replace their targets only when
complete: an existing BVH therefore means a finished file (what ``--batch`` resumes on). A motion output
ending in ``.vrma`` is a VRM Animation (:mod:`gesturecast.bridges.vrma`), any other a BVH.
"""

from __future__ import annotations

import logging
from contextlib import ExitStack
from dataclasses import replace
from pathlib import Path

import numpy as np

from gesturecast.bridges.pose_json import PoseJsonWriter
from gesturecast.bridges.vrma import FOLDED, VrmaWriter
from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.canonical_bvh import CanonicalBvhWriter
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.sources import FastFileSource
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.run.engine import EngineReport, make_report, offline_batches
from gesturecast.realtime.timing.scheduler import STAGE_SINK
from gesturecast.settings import FACE_OFF, LIPSYNC_OFF, Settings

BVH_SUFFIX = ".bvh"
VRMA_SUFFIX = ".vrma"
JSON_SUFFIX = ".json"
MOTION_SUFFIXES = (BVH_SUFFIX, VRMA_SUFFIX)
OUTPUT_SUFFIXES = (*MOTION_SUFFIXES, JSON_SUFFIX)  # what ``generate -o`` writes

logger = logging.getLogger(__name__)


class BvhFrameWriter(CanonicalBvhWriter):
    """The BVH writer fed PoseFrame batches, like the JSON and VRMA writers."""

    def write(self, frames: list[PoseFrame]) -> None:
        if frames:
            self.append(np.stack([f.rotations for f in frames]),  # (n, J, 4)
                        np.stack([f.root_position for f in frames]))  # (n, 3)


def check_motion_path(path: Path, flag: str, suffixes: tuple[str, ...] = MOTION_SUFFIXES) -> Path:
    """``path`` when its suffix is one of ``suffixes`` (a motion format: .bvh, .vrma); a one-line error naming
    ``flag`` and every suffix accepted otherwise."""
    if path.suffix.lower() not in suffixes:
        names = ", ".join(suffixes[:-1]) + f" or {suffixes[-1]}" if len(suffixes) > 1 else suffixes[0]
        raise UserError(f"{flag} {path}: name a {names} file (the suffix picks the format)")
    return path


def motion_writer(path: Path, vrma_bones: str = FOLDED) -> BvhFrameWriter | VrmaWriter:
    """The writer that the file name asks for: ``.vrma`` → VRM Animation (``vrma_bones``: UpperChest ``"folded"``
    into Chest, or ``"full"``), ``.bvh`` → BVH."""
    if check_motion_path(path, "output").suffix.lower() == VRMA_SUFFIX:
        return VrmaWriter(path, skeleton=CANONICAL_WITH_HANDS, bones=vrma_bones)
    return BvhFrameWriter(path, skeleton=CANONICAL_WITH_HANDS)


def frame_writer(path: Path, viseme_names: tuple[str, ...], face_names: tuple[str, ...] = ()
                 ) -> BvhFrameWriter | VrmaWriter | PoseJsonWriter:
    """A motion writer, or the pose-stream JSON writer for ``.json``; another suffix is a one-line error."""
    if path.suffix.lower() == JSON_SUFFIX:
        return PoseJsonWriter(path, viseme_names, face_names)
    return motion_writer(check_motion_path(path, "output", OUTPUT_SUFFIXES))


def body_only(settings: Settings, motion_paths: list[Path], json_path: Path | None) -> Settings:
    """``settings`` without lip sync and face when no output carries them (BVH files only: a .vrma and the JSON carry
    visemes and face weights); the body is the same bit for bit, and the visemes' and face's CPU is not spent."""
    if json_path is not None or any(path.suffix.lower() != BVH_SUFFIX for path in motion_paths):
        return settings
    return replace(settings, lipsync=LIPSYNC_OFF, face=FACE_OFF)


def generate_to_files(session: GestureSession, audio: Path, motion_paths: list[Path], json_path: Path | None = None,
                      vrma_bones: str = FOLDED) -> EngineReport:
    """Run ``session`` over ``audio`` as fast as possible; write each motion file (BVH or .vrma, by suffix; a .vrma
    with ``vrma_bones``) and the JSON; returns the run's report.

    Raises :class:`UserError` for a bad audio file or one shorter than a motion frame (no output is left).
    """
    source = FastFileSource(audio)
    with ExitStack() as files:
        writers = [files.enter_context(motion_writer(path, vrma_bones)) for path in motion_paths]
        if json_path is not None:
            writers.append(files.enter_context(PoseJsonWriter(json_path, session.viseme_names, session.face_names,
                                                              closing=lambda: {"gesture_cues": cue_report(session)})))
        for batch in offline_batches(session, source):
            with session.stats.time(STAGE_SINK):  # the outputs: the live engine's bridges, here the file writers
                for writer in writers:
                    writer.write(batch)
        if writers[0].num_frames == 0:
            raise UserError(f"{audio} is shorter than one motion frame (1/30 s)")
        with session.stats.time(STAGE_SINK):
            for writer in writers:
                writer.save()
    report = make_report(session, source.stats(), {})
    logger.info("wrote %d frames (%.1f s) to %s; rtf %.3f (CPU of every stage per second of audio)",
                writers[0].num_frames, writers[0].num_frames / MOTION_FPS,
                ", ".join(str(path) for path in [*motion_paths, json_path] if path is not None), report.rtf)
    return report


def cue_report(session: GestureSession) -> dict:
    """The session's gesture cues by outcome, and a line for each recent one not on time."""
    cues = session.gestures.cues
    return {**cues.summary(), "notes": [o.describe() for o in cues.outcomes if o.status != "on time"]}

