"""The canonical skeleton as a BVH hierarchy, shared by :func:`motion_to_bvh` and the BVH recorder.

Units: centimetres (the BVH convention of ZeroEGGS, Mixamo and Bandai Namco; in Blender's
importer set Scale to 0.01 for a life-size character). Y-up, the character faces +Z. Every
joint has ``Zrotation Yrotation Xrotation`` channels; the root also has positions first.
"""

from __future__ import annotations

import shutil
import tempfile
from contextlib import suppress
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import atomic_file, check_output_target
from gesturecast.models.motion.bvh import BvhData, format_header, format_motion_rows, rotation_channel_values
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL, END_SITES, FINGERTIPS, Skeleton

BVH_UNITS_PER_METRE = 100.0
ROTATION_ORDER = "ZYX"
_ROTATION_CHANNELS = tuple(f"{axis}rotation" for axis in ROTATION_ORDER)
_ROOT_CHANNELS = ("Xposition", "Yposition", "Zposition", *_ROTATION_CHANNELS)


def canonical_frame_values(
    rotations: np.ndarray, root_position: np.ndarray, skeleton: Skeleton = CANONICAL
) -> np.ndarray:
    """BVH channel values for canonical poses: (T, J, 4), (T, 3) metres -> (T, 3 + 3 J), joints depth-first."""
    euler = rotation_channel_values(rotations[:, skeleton.depth_first_order()], ROTATION_ORDER)  # (T, J, 3) degrees
    flat = euler.reshape(len(euler), 3 * rotations.shape[1])  # (T, 3 J)
    return np.concatenate([root_position * BVH_UNITS_PER_METRE, flat], axis=1)


def canonical_bvh_data(
    rotations: np.ndarray, root_position: np.ndarray, fps: float, skeleton: Skeleton = CANONICAL
) -> BvhData:
    """A BVH document of canonical poses (rotations (T, J, 4), root_position (T, 3) metres)."""
    channels = [_ROOT_CHANNELS] + [_ROTATION_CHANNELS] * (skeleton.num_joints - 1)
    order = skeleton.depth_first_order()  # (J,) skeleton index of each BVH joint
    file_index = np.argsort(order)  # (J,) BVH index of each skeleton joint
    names = [skeleton.names[j] for j in order]
    leaves = set(names) - {skeleton.names[p] for p in skeleton.parents if p >= 0}  # joints that end a chain
    end_sites = {
        names.index(name): np.asarray(offset) * BVH_UNITS_PER_METRE
        for name, offset in {**END_SITES, **FINGERTIPS}.items()
        if name in leaves
    }
    return BvhData(
        names=names,
        parents=np.array([file_index[skeleton.parents[j]] if skeleton.parents[j] >= 0 else -1 for j in order]),
        offsets=skeleton.offsets[order] * BVH_UNITS_PER_METRE,
        channels=channels,
        frame_time=1.0 / fps,
        motion=canonical_frame_values(rotations, root_position, skeleton),
        end_sites=end_sites,
    )


def canonical_layout(fps: float, skeleton: Skeleton = CANONICAL) -> BvhData:
    """The canonical BVH document with no frames: what a header is formatted from."""
    return canonical_bvh_data(np.zeros((0, skeleton.num_joints, 4)), np.zeros((0, 3)), fps, skeleton)


class CanonicalBvhWriter:
    """Canonical poses appended in batches, saved as one BVH (the same bytes as ``motion_to_bvh``).

    Memory stays bounded however long the take: frame lines are spooled to an unnamed temporary
    file in the target's folder; :meth:`save` writes header and frames atomically
    (:func:`gesturecast.files.atomic_file`), :meth:`close` drops the spool.
    """

    def __init__(self, path: str | Path, fps: float = MOTION_FPS, skeleton: Skeleton = CANONICAL) -> None:
        self.path = Path(path)
        self.skeleton = skeleton
        self.fps = fps
        self.num_frames = 0
        target = check_output_target(self.path)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            self._spool = tempfile.TemporaryFile(  # noqa: SIM115 (closed by close())
                "w+", encoding="utf-8", newline="\n", dir=target.parent)
        except OSError as error:
            raise UserError(f"cannot write {self.path}: {error.strerror}") from None

    def append(self, rotations: np.ndarray, root_position: np.ndarray) -> None:
        """Add frames: rotations (T, J, 4) XYZW, root_position (T, 3) metres."""
        try:
            self._spool.write(format_motion_rows(canonical_frame_values(rotations, root_position, self.skeleton)))
        except OSError as error:
            raise UserError(f"cannot write {self.path}: {error.strerror}") from None
        self.num_frames += len(rotations)

    def save(self) -> None:
        """Write the BVH file (replacing ``path`` in one step)."""
        layout = canonical_layout(self.fps, self.skeleton)
        with atomic_file(self.path) as handle:
            handle.write(format_header(layout, self.num_frames))
            self._spool.seek(0)
            shutil.copyfileobj(self._spool, handle)

    def close(self) -> None:
        """Drop the spool (a failing flush of lines already saved, or never to be saved, changes nothing)."""
        with suppress(OSError):
            self._spool.close()

    def __enter__(self) -> CanonicalBvhWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
