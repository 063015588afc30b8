"""One audio file → a BVH (and optionally the pose stream as JSON): the per-file work of ``generate``.

``gesturecast generate FILE`` and every worker of ``generate --batch`` call :func:`generate_to_files`,
so a batch writes exactly the bytes the single-file command writes. The session is fed by the unpaced
file source (:func:`gesturecast.realtime.engine.offline_batches`), frames are streamed into the
atomic writers (constant memory on any duration), and the outputs replace their targets only when
complete: an existing BVH therefore means a finished file (what ``--batch`` resumes on).
"""

from __future__ import annotations

import logging
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.canonical_bvh import CanonicalBvhWriter
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.sources import FastFileSource
from gesturecast.realtime.engine import EngineReport, make_report, offline_batches
from gesturecast.realtime.pose_json import PoseJsonWriter
from gesturecast.realtime.session import GestureSession

logger = logging.getLogger(__name__)


def generate_to_files(session: GestureSession, audio: Path, bvh_path: Path, json_path: Path | None = None
                      ) -> EngineReport:
    """Run ``session`` over ``audio`` as fast as possible; write the BVH (and JSON); returns the run's report.

    Raises :class:`UserError` for a bad audio file or one shorter than a motion frame (no output is left).
    """
    source = FastFileSource(audio)
    with ExitStack() as files:
        bvh = files.enter_context(CanonicalBvhWriter(bvh_path, skeleton=CANONICAL_WITH_HANDS))
        poses = files.enter_context(PoseJsonWriter(json_path, session.viseme_names)) if json_path is not None else None
        for batch in offline_batches(session, source):
            if batch:
                bvh.append(np.stack([f.rotations for f in batch]),  # (n, J, 4)
                           np.stack([f.root_position for f in batch]))  # (n, 3)
            if poses is not None:
                poses.write(batch)
        if bvh.num_frames == 0:
            raise UserError(f"{audio} is shorter than one motion frame (1/30 s)")
        bvh.save()
        if poses is not None:
            poses.save()
    report = make_report(session, source, {})
    logger.info("wrote %d frames (%.1f s) to %s; rtf %.3f", bvh.num_frames, bvh.num_frames / MOTION_FPS,
                bvh_path, report.rtf)
    return report
