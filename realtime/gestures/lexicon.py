"""The gesture lexicon: short canonical-skeleton clips of gestures that mean something, with their trigger words.

The generator imposes a lexicon clip's body-part latents while it denoises the window where a trigger
word falls (inpainting), so the avatar waves at "hello". This module holds the lexicon in memory, reads a built
one and reads a user's own folder of clips; the lexicon shipped with the package is built offline from the
labelled Bandai Namco takes (:mod:`gesturecast.tools.gestures.build`, ``gesturecast gestures
build``). Numpy only (no torch).

**Files** (``models/weights/gestures/``): ``lexicon.json`` (entries, parts, strokes, trigger words, styles,
source takes, rules, licence) and ``clips.npz`` (one float16 (T, 136) array per gesture, style and take, key
``"<name>.<style>.<take>"``). A style may hold several takes (different recordings of the gesture, take 0 the
default); the performances of a stream play them in turn. Reading them needs numpy and json only.

**A user's lexicon** (:func:`load_lexicon` on a folder with ``gestures.json``): name → ``clip`` (a BVH or
SMPL-X file in the folder, read with the same retargeting), ``triggers`` (non-empty), optional ``parts``
(default arms), optional ``stroke`` (seconds from the clip start; default: the frame where the wrists and head are
farthest from the clip's first pose, at its arrival: :mod:`.strokes`), optional ``style`` (default
neutral) and an optional folder-level ``joint_map`` for a skeleton that is not detected automatically. User clips
are not trimmed. A bad entry raises a one-line :class:`UserError` naming the file and the field.
"""

from __future__ import annotations

import math
import re
import zipfile
from collections.abc import Callable, Container
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.input_files import MIB
from gesturecast.models.motion.body_parts import PART_NAMES
from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.realtime.gestures.lexicon_checks import (
    MIN_CLIP_S,
    ClipArchive,
    built_fps,
    check_built_item,
    inside,
    read_json,
    user_clip_path,
)
from gesturecast.realtime.gestures.strokes import body_frame_positions, pose_distance, stroke_frame

FORMAT_VERSION = 2  # 2: several takes per style (``take``); 1 held one clip per style
LEXICON_FILE = "lexicon.json"
CLIPS_FILE = "clips.npz"
USER_MAPPING_FILE = "gestures.json"
MAX_MAPPING_BYTES = MIB  # a mapping file names a few dozen clips: 1 MiB is far more
MAX_LEXICON_BYTES = 64 * MIB  # lexicon.json / clips.npz of a built lexicon (the shipped one is well under 2 MB)
DEFAULT_STYLE = "neutral"

_NAME = re.compile(r"^[a-z0-9][a-z0-9-]*$")


# ---------------------------------------------------------------------------------------------------------------
# the lexicon in memory


@dataclass(frozen=True)
class GestureVariant:
    """One take of a gesture in one style: its motion features (T, D) and stroke frame, and where it came from."""

    style: str
    features: np.ndarray  # (T, FEATURE_DIM), float16 as shipped, float32 for a user clip
    stroke_frame: int
    source: str
    fps: float = MOTION_FPS
    source_start: int = 0  # first frame of the clip in the source take
    hand: str = ""
    removed: tuple[int, int] | None = None  # source take frames [a, b) cut out of a long hold
    take: int = 0  # which recording of this style (0: the default)

    @property
    def num_frames(self) -> int:
        return int(self.features.shape[0])

    @property
    def duration(self) -> float:
        return self.num_frames / self.fps

    @property
    def stroke_time(self) -> float:
        return self.stroke_frame / self.fps


@dataclass(frozen=True)
class GestureEntry:
    """A named gesture: the body parts it moves, its trigger words and one or more takes per style (take 0 of
    each style first)."""

    name: str
    parts: tuple[str, ...]
    triggers: tuple[str, ...]
    variants: tuple[GestureVariant, ...]
    description: str = ""

    @property
    def styles(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(v.style for v in self.variants))

    def variant(self, style: str | None = None) -> GestureVariant:
        """The first take of ``style`` (any spelling of a style: "normal", "elderly"); the default (neutral, else
        the first) when the gesture has no such clip or ``style`` is None."""
        from gesturecast.models.generator.styles import canonical_style

        by_style: dict[str, GestureVariant] = {}
        for v in self.variants:
            by_style.setdefault(v.style, v)
        if style is not None:
            try:
                style = canonical_style(style)
            except UserError:  # a free-text style prompt, not a label
                style = None
        if style in by_style:
            return by_style[style]
        return by_style.get(DEFAULT_STYLE, self.variants[0])

    def takes(self, style: str) -> tuple[GestureVariant, ...]:
        """Every take of ``style`` (a canonical style this gesture has), in lexicon order."""
        return tuple(v for v in self.variants if v.style == style)

    @property
    def duration(self) -> float:
        return self.variant().duration

    @property
    def stroke_time(self) -> float:
        return self.variant().stroke_time


RENAMED = {"bye": "hand-up"}  # a shipped gesture's old name -> its name now (named by what it shows); both work


def current_name(name: str, known: Container[str]) -> str:
    """``name``, or the name a renamed shipped gesture has now when the lexicon (``known``) has that and not ``name``
    (``bye`` → ``hand-up``; a user's own ``bye`` stays theirs)."""
    renamed = RENAMED.get(name)
    return renamed if name not in known and renamed in known else name


@dataclass
class Lexicon:
    """Gestures by name, and where they were read from."""

    entries: dict[str, GestureEntry]
    source: str = ""
    license: str = ""
    metadata: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> GestureEntry:
        return self.entries[name]

    def __contains__(self, name: object) -> bool:
        return name in self.entries

    def __iter__(self):
        return iter(self.entries.values())

    def __len__(self) -> int:
        return len(self.entries)

    def triggers(self) -> dict[str, str]:
        """Trigger word or phrase (lower case) → gesture name; the first gesture listing it wins."""
        table: dict[str, str] = {}
        for entry in self.entries.values():
            for word in entry.triggers:
                table.setdefault(word.lower(), entry.name)
        return table

    def summary(self) -> list[dict]:
        """One JSON-ready row per gesture (what ``gesturecast gestures list`` prints)."""
        return [{"name": e.name, "parts": list(e.parts), "duration": round(e.duration, 3),
                 "stroke": round(e.stroke_time, 3), "styles": list(e.styles), "triggers": list(e.triggers),
                 "variants": [{"style": v.style, "take": v.take, "duration": round(v.duration, 3),
                               "stroke": round(v.stroke_time, 3), "source": v.source} for v in e.variants]}
                for e in self.entries.values()]


# ---------------------------------------------------------------------------------------------------------------
# reading


def _fail(path: Path, message: str) -> UserError:
    return UserError(f"{path}: {message}")


def read_built_lexicon(folder: Path) -> Lexicon:
    """A lexicon written by ``gesturecast gestures build`` (:mod:`gesturecast.tools.gestures.build`;
    numpy + json only)."""
    folder = Path(folder)
    path = folder / LEXICON_FILE
    raw = read_json(path, MAX_LEXICON_BYTES, "gesture lexicon")
    if not isinstance(raw, dict) or not isinstance(raw.get("gestures"), list):
        raise _fail(path, "not a gesture lexicon (no 'gestures' list)")
    if raw.get("format_version") != FORMAT_VERSION:
        raise _fail(path, f"format_version {raw.get('format_version')!r} is not {FORMAT_VERSION}; rebuild it with "
                          "`gesturecast gestures build`")
    clips_path = inside(folder, str(raw.get("clips", CLIPS_FILE)))
    if clips_path is None or not clips_path.is_file():
        raise _fail(path, f"'clips' {raw.get('clips', CLIPS_FILE)!r} is not a file in {folder}")
    if clips_path.stat().st_size > MAX_LEXICON_BYTES:
        raise _fail(clips_path, "larger than 64 MiB, more than a gesture lexicon holds")
    fps = built_fps(raw.get("fps", MOTION_FPS), path)
    entries = {}
    try:
        with ClipArchive(clips_path) as clips:
            for index, item in enumerate(raw["gestures"]):
                check_built_item(item, index, path)
                variants = []
                for v in item["variants"]:
                    features = clips[v["clip"]]
                    if features.ndim != 2 or features.shape[1] != FEATURE_DIM:
                        raise _fail(clips_path, f"clip {v['clip']} has shape {features.shape}, expected (T, "
                                                f"{FEATURE_DIM})")
                    variants.append(GestureVariant(v["style"], features, int(v["stroke_frame"]), v.get("source", ""),
                                                   fps, int(v.get("source_start", 0)), v.get("hand", ""),
                                                   tuple(v["removed"]) if v.get("removed") else None,
                                                   int(v.get("take", 0))))
                entries[item["name"]] = GestureEntry(item["name"], tuple(item["parts"]), tuple(item["triggers"]),
                                                     tuple(variants), item.get("description", ""))
    except (KeyError, TypeError, ValueError, zipfile.BadZipFile, OSError) as error:
        if isinstance(error, UserError):
            raise
        raise _fail(path, f"damaged gesture lexicon ({type(error).__name__}: {error})") from None
    meta = {k: v for k, v in raw.items() if k not in ("gestures",)}
    return Lexicon(entries, source=str(raw.get("source", "")), license=str(raw.get("license", "")), metadata=meta)


def _default_reader(joint_map: Path | None) -> Callable[[Path], SkeletonMotion]:
    def read(path: Path) -> SkeletonMotion:
        from gesturecast.models.motion.motion_features import face_forward
        from gesturecast.models.motion.retarget import load_motion_file

        return face_forward(load_motion_file(path, joint_map))
    return read


def _user_entry(name: str, item: object, folder: Path, mapping: Path,
                read: Callable[[Path], SkeletonMotion]) -> GestureEntry:
    from gesturecast.models.generator.styles import canonical_style
    from gesturecast.models.motion.motion_features import motion_to_features

    where = f"gesture {name!r}"
    if not _NAME.match(name):
        raise _fail(mapping, f"{where}: a name is lower-case letters, digits and '-'")
    if not isinstance(item, dict):
        raise _fail(mapping, f"{where} must be an object with 'clip' and 'triggers'")
    unknown = sorted(set(item) - {"clip", "triggers", "parts", "stroke", "style", "description"})
    if unknown:
        raise _fail(mapping, f"{where}: unknown field {unknown[0]!r} (fields: clip, triggers, parts, stroke, style, "
                             "description)")
    clip = item.get("clip")
    if not isinstance(clip, str) or not clip:
        raise _fail(mapping, f"{where}: 'clip' must name a motion file in {folder}")
    clip_path = user_clip_path(folder, clip, where, mapping)
    triggers = item.get("triggers")
    if isinstance(triggers, str):
        triggers = [triggers]
    if (not isinstance(triggers, list) or not triggers
            or not all(isinstance(t, str) and t.strip() for t in triggers)):
        raise _fail(mapping, f"{where}: 'triggers' must be a non-empty list of words or phrases")
    parts = item.get("parts", ["arms"])
    if isinstance(parts, str):
        parts = [parts]
    if not isinstance(parts, list) or not parts or not all(isinstance(p, str) for p in parts):
        raise _fail(mapping, f"{where}: 'parts' must be a non-empty list of {', '.join(PART_NAMES)}")
    bad = [p for p in parts if p not in PART_NAMES]
    if bad:
        raise _fail(mapping, f"{where}: unknown part {bad[0]!r} in 'parts' (parts: {', '.join(PART_NAMES)})")
    style = item.get("style", DEFAULT_STYLE)
    try:
        style = canonical_style(style) if isinstance(style, str) else None
    except UserError:
        style = None
    if style is None:
        raise _fail(mapping, f"{where}: 'style' {item.get('style')!r} is not a known style")
    motion = read(clip_path)
    if motion.num_frames < 2 or motion.duration < MIN_CLIP_S:
        raise _fail(mapping, f"{where}: 'clip' {clip} holds {motion.num_frames} frames ({motion.duration:.2f} s); a "
                             f"gesture clip is at least {MIN_CLIP_S} s")
    stroke = item.get("stroke")
    if stroke is None:
        stroke_index = stroke_frame(pose_distance(body_frame_positions(motion)))
    else:
        if isinstance(stroke, bool) or not isinstance(stroke, (int, float)) or not math.isfinite(stroke):
            raise _fail(mapping, f"{where}: 'stroke' must be a time in seconds from the clip start")
        if not 0.0 <= stroke < motion.duration:
            raise _fail(mapping, f"{where}: 'stroke' {stroke:g} s is outside the clip ({clip}: 0 to "
                                 f"{motion.duration:.2f} s)")
        stroke_index = min(motion.num_frames - 1, int(round(stroke * motion.fps)))
    variant = GestureVariant(style, motion_to_features(motion), stroke_index, clip, motion.fps)
    ordered_parts = tuple(p for p in PART_NAMES if p in parts)
    return GestureEntry(name, ordered_parts, tuple(t.strip() for t in triggers), (variant,),
                        str(item.get("description", "")))


def read_user_lexicon(folder: Path, read: Callable[[Path], SkeletonMotion] | None = None) -> Lexicon:
    """A user's folder: ``gestures.json`` (name → clip, triggers, parts, stroke, style; module docstring) and the
    clips it names, retargeted like the training data. Bad entries raise a one-line :class:`UserError`."""
    folder = Path(folder)
    mapping = folder / USER_MAPPING_FILE
    raw = read_json(mapping, MAX_MAPPING_BYTES, "gesture mapping")
    if not isinstance(raw, dict):
        raise _fail(mapping, "must be a JSON object: gesture name -> {clip, triggers, parts, stroke}")
    joint_map = raw.pop("joint_map", None)
    if joint_map is not None:
        if not isinstance(joint_map, str) or not (folder / joint_map).is_file():
            raise _fail(mapping, f"'joint_map' must name a joint map file in {folder}")
        joint_map = folder / joint_map
    if not raw:
        raise _fail(mapping, "names no gestures")
    reader = read or _default_reader(joint_map)
    entries = {}
    for name, item in raw.items():
        try:
            entries[name] = _user_entry(name, item, folder, mapping, reader)
        except UserError as error:
            message = str(error)
            raise (error if str(mapping) in message else _fail(mapping, f"gesture {name!r}: {message}")) from None
    return Lexicon(entries, source=str(folder), license="")


def default_lexicon_dir() -> Path:
    """The lexicon shipped with the package (``models/weights/gestures``)."""
    from importlib import resources

    return Path(str(resources.files("gesturecast.models"))) / "weights" / "gestures"


def load_lexicon(folder: Path | None = None) -> Lexicon:
    """The built lexicon in ``folder`` (``lexicon.json``), a user folder (``gestures.json``), or, with None, the
    shipped one."""
    folder = default_lexicon_dir() if folder is None else Path(folder)
    if not folder.is_dir():
        raise UserError(f"gesture folder not found: {folder}")
    if (folder / LEXICON_FILE).is_file():
        return read_built_lexicon(folder)
    if (folder / USER_MAPPING_FILE).is_file():
        return read_user_lexicon(folder)
    raise UserError(f"{folder} holds neither {LEXICON_FILE} (a built lexicon) nor {USER_MAPPING_FILE} (your clips)")
