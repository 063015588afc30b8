"""Reading and writing BVH motion-capture files.

A small self-contained reader/writer (numpy only). It accepts any channel order, position
channels on non-root joints, ``End Site`` blocks, CRLF line endings and any frame rate.
Rotation channels are intrinsic Euler angles in degrees, applied in channel order:
``Zrotation Xrotation Yrotation`` means ``R = Rz @ Rx @ Ry``. A joint with position channels
takes its local translation from them (they replace its OFFSET, as Blender and MotionBuilder
read them); other joints are translated by their OFFSET.

Bad input raises :class:`~gesturecast.errors.UserError` with one line naming the problem. Every number
must be finite, and every length (an OFFSET, an End Site, a position channel value) at most
:data:`MAX_BVH_LENGTH` file units from zero. A rotation channel may hold any finite angle: one beyond a full turn is
read modulo 360° (exactly, so 1e308° is as good a rotation as any).
"""

from __future__ import annotations

import itertools
import math
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.input_files import read_bounded
from gesturecast.models.motion.motion import MAX_MOTION_FILE_BYTES, check_clip_header, check_file_size
from gesturecast.models.motion.rotations import quat_from_euler, quat_identity, quat_to_euler

_AXES = "XYZ"
_VALID_CHANNELS = tuple(f"{a}{kind}" for kind in ("position", "rotation") for a in _AXES)
_FLOAT_FORMAT = "%.6f"  # 1e-6 degree / 1e-6 file unit: far below the 1e-4 degree round-trip bound
_INDENT = "\t"
MAX_JOINT_DEPTH = 256  # deeper nesting is no skeleton (and would exhaust the recursion limit)
# the largest |OFFSET|, End Site or position channel value, in file units: 1 km in centimetres (the usual BVH
# unit), 100 m in millimetres; no capture volume or skeleton is larger (metre files are bounded after
# retargeting: MAX_ROOT_METRES)
MAX_BVH_LENGTH = 1e5
_NON_BLANK_LINE = re.compile(r"[^\r\n]*\S[^\r\n]*")


def within_a_turn(degrees: np.ndarray) -> np.ndarray:
    """Angles beyond ±360° reduced modulo 360° (exact for any finite float: no overflow in the radians and sines
    after); the others as they are."""
    return np.where(np.abs(degrees) > 360.0, np.remainder(degrees, 360.0), degrees)


@dataclass
class BvhData:
    """The content of one BVH file.

    names: joint names in file order (parents before children).
    parents: (J,) parent index per joint, -1 for the root.
    offsets: (J, 3) rest offsets from the parent, in file units.
    channels: per joint, its channel names in file order (e.g. ``("Zrotation", "Yrotation", "Xrotation")``).
    end_sites: joint index -> (3,) offset of its ``End Site``.
    frame_time: seconds per frame.
    motion: (T, C) channel values per frame (degrees for rotations, file units for positions).
    """

    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray
    channels: list[tuple[str, ...]]
    frame_time: float
    motion: np.ndarray
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)

    @property
    def num_joints(self) -> int:
        return len(self.names)

    @property
    def num_frames(self) -> int:
        return self.motion.shape[0]

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    def channel_columns(self) -> list[np.ndarray]:
        """Per joint, the column indices of its channels in :attr:`motion`."""
        starts = np.cumsum([0] + [len(c) for c in self.channels])
        return [np.arange(starts[j], starts[j + 1]) for j in range(self.num_joints)]

    def local_rotations(self) -> np.ndarray:
        """Local joint rotations (T, J, 4) XYZW from the rotation channels (identity where none)."""
        rotations = quat_identity((self.num_frames, self.num_joints))
        for j, (names, columns) in enumerate(zip(self.channels, self.channel_columns(), strict=True)):
            pairs = zip(names, columns, strict=True)
            rot = [(name[0].upper(), col) for name, col in pairs if name.endswith("rotation")]
            if rot:
                order = "".join(axis for axis, _ in rot)
                angles = np.deg2rad(within_a_turn(self.motion[:, [col for _, col in rot]]))  # (T, n_rot)
                rotations[:, j] = quat_from_euler(angles, order)
        return rotations

    def local_translations(self) -> np.ndarray:
        """Local joint translations (T, J, 3) in file units: position channels where present, else OFFSET."""
        translations = np.repeat(self.offsets[None], self.num_frames, axis=0)  # (T, J, 3)
        for j, (names, columns) in enumerate(zip(self.channels, self.channel_columns(), strict=True)):
            for name, col in zip(names, columns, strict=True):
                if name.endswith("position"):
                    translations[:, j, _AXES.index(name[0].upper())] = self.motion[:, col]
        return translations


def rotation_channel_values(rotations: np.ndarray, order: str) -> np.ndarray:
    """Euler channel values in degrees for the given channel order. (..., 4) -> (..., 3)."""
    return np.rad2deg(quat_to_euler(rotations, order))


# ----------------------------------------------------------------------------- reading


class _Tokens:
    """A cursor over the whitespace-separated tokens of the hierarchy section."""

    def __init__(self, tokens: list[str], path: Path) -> None:
        self.tokens = tokens
        self.pos = 0
        self.path = path

    def next(self, what: str) -> str:
        if self.pos >= len(self.tokens):
            raise UserError(f"{self.path}: truncated BVH file (ended while reading {what})")
        token = self.tokens[self.pos]
        self.pos += 1
        return token

    def expect(self, expected: str) -> None:
        token = self.next(f"'{expected}'")
        if token != expected:
            raise UserError(f"{self.path}: malformed BVH hierarchy: expected '{expected}', found '{token}'")

    def number(self, what: str) -> float:
        token = self.next(what)
        try:
            return float(token)
        except ValueError:
            raise UserError(f"{self.path}: malformed BVH {what}: '{token}' is not a number") from None


@dataclass
class _Hierarchy:
    names: list[str] = field(default_factory=list)
    parents: list[int] = field(default_factory=list)
    offsets: list[list[float]] = field(default_factory=list)
    channels: list[tuple[str, ...]] = field(default_factory=list)
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)


def check_length(value: float, what: str, path: Path) -> None:
    """Refuse a BVH length (OFFSET, End Site or position value) that is not finite or beyond MAX_BVH_LENGTH."""
    if not math.isfinite(value):
        raise UserError(f"{path}: BVH {what} holds a NaN or infinite value")
    if abs(value) > MAX_BVH_LENGTH:
        raise UserError(f"{path}: BVH {what} value {value:g} is beyond the supported ±{MAX_BVH_LENGTH:g} file units "
                        "(1 km in centimetres)")


def _read_offset(tokens: _Tokens, what: str) -> list[float]:
    """The three numbers of an ``OFFSET`` line, each finite and within :data:`MAX_BVH_LENGTH`."""
    tokens.expect("OFFSET")
    values = [tokens.number("OFFSET value") for _ in range(3)]
    for value in values:
        check_length(value, what, tokens.path)
    return values


def _read_channels(tokens: _Tokens) -> tuple[str, ...]:
    tokens.expect("CHANNELS")
    count_token = tokens.next("channel count")
    if not count_token.isdigit():
        raise UserError(f"{tokens.path}: malformed BVH CHANNELS line: '{count_token}' is not a count")
    names = []
    for _ in range(int(count_token)):
        name = tokens.next("channel name")
        canonical = name[0].upper() + name[1:].lower()
        if canonical not in _VALID_CHANNELS:
            raise UserError(f"{tokens.path}: unknown BVH channel '{name}' (expected e.g. Xposition, Zrotation)")
        names.append(canonical)
    return tuple(names)


def _read_joint(tokens: _Tokens, hierarchy: _Hierarchy, parent: int, depth: int = 0) -> None:
    """Read one ``ROOT``/``JOINT`` block (its keyword already consumed) and its children."""
    if depth >= MAX_JOINT_DEPTH:
        raise UserError(f"{tokens.path}: BVH joints nested more than {MAX_JOINT_DEPTH} deep; not a skeleton")
    index = len(hierarchy.names)
    name = tokens.next("joint name")
    hierarchy.names.append(name)
    hierarchy.parents.append(parent)
    tokens.expect("{")
    hierarchy.offsets.append(_read_offset(tokens, f"joint '{name}' OFFSET"))
    hierarchy.channels.append(_read_channels(tokens))
    while True:
        keyword = tokens.next("joint block")
        if keyword == "}":
            return
        if keyword == "JOINT":
            _read_joint(tokens, hierarchy, index, depth + 1)
        elif keyword == "End":
            tokens.expect("Site")
            tokens.expect("{")
            hierarchy.end_sites[index] = np.array(_read_offset(tokens, f"End Site of joint '{name}' OFFSET"))
            tokens.expect("}")
        else:
            raise UserError(f"{tokens.path}: malformed BVH hierarchy: unexpected '{keyword}' in joint block")


def _split_sections(text: str, path: Path) -> tuple[str, int]:
    """The hierarchy text and where the text after ``MOTION`` starts."""
    stripped = text.lstrip("\ufeff \t\r\n")
    if not stripped.startswith("HIERARCHY"):
        raise UserError(f"{path}: not a BVH file (it does not start with HIERARCHY)")
    motion = text.find("MOTION", len(text) - len(stripped))
    if motion < 0:
        raise UserError(f"{path}: truncated BVH file (no MOTION section)")
    return text[len(text) - len(stripped):motion], motion + len("MOTION")


def _header_value(line: str, label: str, path: Path) -> str:
    if not line.strip().startswith(label):
        raise UserError(f"{path}: truncated or malformed BVH MOTION section (missing '{label}')")
    return line.strip()[len(label):].strip()


def _parse_motion(text: str, start: int, num_channels: int, path: Path) -> tuple[float, np.ndarray]:
    """The frame time and the (T, C) channel values of the MOTION section at ``text[start:]``, read row by row into
    the array (no list of every value: a 70 MB file took 13 times its size)."""
    lines = (match.group() for match in _NON_BLANK_LINE.finditer(text, start))
    frames_text = _header_value(next(lines, ""), "Frames:", path)
    time_text = _header_value(next(lines, ""), "Frame Time:", path)
    try:
        num_frames, frame_time = int(frames_text), float(time_text)
    except ValueError:
        header = f"'Frames: {frames_text}', 'Frame Time: {time_text}'"
        raise UserError(f"{path}: malformed BVH MOTION header ({header})") from None
    if num_frames <= 0:
        raise UserError(f"{path}: BVH file has zero frames")
    if not (math.isfinite(frame_time) and frame_time > 0):
        raise UserError(f"{path}: BVH Frame Time must be a positive finite number, got {time_text}")
    check_clip_header(1.0 / frame_time, num_frames, str(path))
    motion = np.empty((num_frames, num_channels))  # (T, C)
    frames_read = 0
    for frames_read, row in enumerate(itertools.islice(lines, num_frames), start=1):
        _read_row(row, motion[frames_read - 1], frames_read - 1, path)
    if frames_read < num_frames:
        raise UserError(f"{path}: truncated BVH file ({frames_read} of {num_frames} frames present)")
    if not np.isfinite(motion).all():
        frame = int(np.argmax(~np.isfinite(motion).all(axis=1)))
        raise UserError(f"{path}: BVH frame {frame} holds NaN or infinite values")
    return frame_time, motion


def _read_row(row: str, out: np.ndarray, frame: int, path: Path) -> None:
    """One MOTION row's values into ``out`` (C,)."""
    values = row.split()
    if len(values) != out.shape[0]:
        raise UserError(f"{path}: BVH frame {frame} has {len(values)} values, the hierarchy declares {out.shape[0]} "
                        "channels")
    try:
        out[:] = np.array(values, dtype=np.float64)
    except ValueError:
        raise UserError(f"{path}: BVH motion data contains a value that is not a number") from None


def _check_position_channels(hierarchy: _Hierarchy, motion: np.ndarray, path: Path) -> None:
    """Refuse position channel values beyond :data:`MAX_BVH_LENGTH` (a root at 1e30 puts the hips at 1e28 m)."""
    column = 0
    for name, channels in zip(hierarchy.names, hierarchy.channels, strict=True):
        for channel in channels:
            if channel.endswith("position"):
                values = motion[:, column]  # (T,)
                frame = int(np.argmax(np.abs(values)))
                if abs(values[frame]) > MAX_BVH_LENGTH:
                    check_length(float(values[frame]), f"frame {frame} joint '{name}' {channel}", path)
            column += 1


def read_bvh(path: str | Path) -> BvhData:
    """Parse a BVH file. Raises UserError for missing, truncated or malformed files."""
    path = Path(path)
    try:
        status = path.stat()
    except OSError as error:
        raise UserError(f"cannot read BVH file {path}: {error.strerror}") from None
    if not stat.S_ISREG(status.st_mode):  # a device (/dev/zero) or a FIFO has no size to check beforehand
        raise UserError(f"cannot read BVH file {path}: not a regular file")
    check_file_size(status.st_size, str(path))
    text = read_bounded(path, MAX_MOTION_FILE_BYTES, "BVH file").decode("utf-8", errors="replace")  # grown since?
    head, motion_start = _split_sections(text, path)
    tokens = _Tokens(head.split()[1:], path)
    tokens.expect("ROOT")
    hierarchy = _Hierarchy()
    _read_joint(tokens, hierarchy, -1)
    num_channels = sum(len(c) for c in hierarchy.channels)
    frame_time, motion = _parse_motion(text, motion_start, num_channels, path)
    _check_position_channels(hierarchy, motion, path)
    return BvhData(
        names=hierarchy.names,
        parents=np.array(hierarchy.parents),
        offsets=np.array(hierarchy.offsets, dtype=np.float64).reshape(-1, 3),
        channels=hierarchy.channels,
        frame_time=frame_time,
        motion=motion,
        end_sites=hierarchy.end_sites,
    )


# ----------------------------------------------------------------------------- writing


def _format_vector(values: np.ndarray) -> str:
    return " ".join(_FLOAT_FORMAT % v for v in values)


def format_motion_rows(motion: np.ndarray) -> str:
    """Frame lines of the MOTION section, one per row of ``motion`` (T, C), each ending in a newline."""
    row_format = " ".join([_FLOAT_FORMAT] * motion.shape[1]) + "\n"
    return "".join(row_format % tuple(row) for row in motion)


def format_hierarchy(data: BvhData) -> str:
    """The ``HIERARCHY`` section followed by the ``MOTION`` keyword line."""
    children: dict[int, list[int]] = {j: [] for j in range(data.num_joints)}
    for j, p in enumerate(data.parents):
        if p >= 0:
            children[int(p)].append(j)
    lines = ["HIERARCHY"]

    def emit(j: int, depth: int) -> None:
        pad = _INDENT * depth
        keyword = "ROOT" if data.parents[j] < 0 else "JOINT"
        lines.append(f"{pad}{keyword} {data.names[j]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}{_INDENT}OFFSET {_format_vector(data.offsets[j])}")
        lines.append(f"{pad}{_INDENT}CHANNELS {len(data.channels[j])} {' '.join(data.channels[j])}".rstrip())
        for child in children[j]:
            emit(child, depth + 1)
        if j in data.end_sites:
            lines.extend([f"{pad}{_INDENT}End Site", f"{pad}{_INDENT}{{",
                          f"{pad}{_INDENT * 2}OFFSET {_format_vector(data.end_sites[j])}", f"{pad}{_INDENT}}}"])
        lines.append(f"{pad}}}")

    emit(0, 0)
    lines.append("MOTION")
    return "\n".join(lines) + "\n"


def format_frame_time(frame_time: float) -> str:
    return f"Frame Time: {frame_time:.10g}\n"


def _check_writable(data: BvhData) -> None:
    if data.parents[0] != -1 or np.any(data.parents[1:] < 0):
        raise ValueError("BVH data must have exactly one root, listed first")
    if np.any(data.parents[1:] >= np.arange(1, data.num_joints)):
        raise ValueError("BVH joints must be ordered parents-first")
    expected = sum(len(c) for c in data.channels)
    if data.motion.ndim != 2 or data.motion.shape[1] != expected:
        raise ValueError(f"motion must be (T, {expected}), got {data.motion.shape}")


def write_bvh(data: BvhData, path: str | Path) -> None:
    """Write ``data`` to ``path`` atomically (a temporary file in the same folder, then rename)."""
    _check_writable(data)
    write_text_atomic(Path(path), format_header(data, data.num_frames) + format_motion_rows(data.motion))


def format_header(data: BvhData, num_frames: int) -> str:
    """Everything before the first frame line: hierarchy, ``Frames:`` and ``Frame Time:``."""
    return format_hierarchy(data) + f"Frames: {num_frames}\n" + format_frame_time(data.frame_time)

