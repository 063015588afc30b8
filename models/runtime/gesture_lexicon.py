"""The gesture lexicon: short canonical-skeleton clips of gestures that mean something, with their trigger words.

The generator imposes a lexicon clip's body-part latents while it denoises the window where a trigger
word falls (inpainting), so the avatar waves at "hello". This module builds the lexicon from the labelled Bandai
Namco takes, writes and reads it, and reads a user's own folder of clips. Numpy only (no torch).

**Sources** (:data:`GESTURES`): Bandai Namco Research Motion Dataset 1 (``bow``, ``bye`` and ``byebye``, ``guide``,
``call``, ``respond``; 15 styles, ``call`` and ``respond`` in normal only) and the gesture subset of dataset 2
(``wave-*-hand(s)``, ``raise-up-*-hand(s)``; 7 styles, 50 to 200 takes per gesture and style). Every take is read
and retargeted exactly as ``gesturecast data build`` reads it (:func:`read_take`: ``load_motion_file`` then
``face_forward``), and the shipped clips are its motion features (:func:`motion_to_features`, D = 136, 30 fps).

**Body frame.** Every rule reads joint positions relative to the hips, turned into the hips' facing frame of the
same frame (:func:`body_frame_positions`: x = the character's left, y = up, z = forward), so walking or turning
does not count as gesturing.

**Trimming** (:func:`active_segment`). The activity is the summed speed (m/s) of both wrists and the head in the
body frame, smoothed by a centred 5-frame mean. The gesture starts at the first frame where the activity rises
above ``ACTIVE_FRACTION`` (10 %) of its peak and ends at the last frame where it is above it (a held pose in
between, e.g. the bottom of a bow, stays inside), widened by ``MARGIN_SECONDS`` (0.2 s) on each side within the
take. The clip therefore starts and ends close to the resting pose the actor held before and after.

**Stroke** (:func:`stroke_signal`, :func:`stroke_frame`): the moment the gesture means most, as one frame of the
trimmed clip. Each gesture names a rule:

- ``height``: the wrist's height above its shoulder (the UpperArm joint); wave, raise, bye and respond.
- ``bend``: how far the head is forward of the hips; bow, and call (Bandai's "call" is a shout with the hands
  cupped at the mouth, the body leaning well forward).
- ``reach``: the wrist's horizontal distance from its shoulder (the arm held out: a hanging arm has almost none);
  guide.

The hand is the one the gesture names (``left``, ``right``; ``both``: the mean of the two wrists' signals) or,
for ``either``, the hand whose signal varies most inside the clip. The stroke is the peak of the signal inside the
active segment, taken at its arrival: the first frame that comes within ``STROKE_TOLERANCE`` (5 %) of the
signal's range below the peak, so a held pose (a raised arm, the bottom of a bow) gives the moment it is reached
rather than a frame picked by tremor inside the hold.

**Shortening a long hold** (:func:`shorten_hold`). Bandai's waves go on for 6 to 8 s; a clip longer than
``MAX_SECONDS`` (4 s) has part of its hold cut out: from at least ``KEEP_SECONDS`` (1 s) after the stroke to no
later than the release (the last frame where the stroke signal is above half its range), at the pair of frames
whose 3-frame windows match best (no torso, arm or head joint more than ``SPLICE_TOLERANCE``, 3 cm, apart: a
held pose, or a wave at the same phase and direction), cross-faded over ``BLEND_FRAMES`` (4). The rise, the
stroke and the whole retraction stay; a hold that never comes back to the same pose is left whole, so some clips
stay longer than 4 s. ``lexicon.json`` records the source frames removed.

**Variants** (:func:`build_lexicon`): per gesture the first ``MAX_VARIANTS`` (5) styles of ``STYLE_PREFERENCE``
(neutral, i.e. Bandai's "normal", then happy, sad, old, proud, tired, active) that have a take whose clip starts
and ends with both arms down (:func:`at_rest`: the wrists at least ``REST_DROP``, 25 cm, below the shoulders;
some dataset-1 takes start or end mid-gesture); per style the one of those takes whose clip length is the median
(a typical performance, not the longest or the shortest).

**Files** (``models/weights/gestures/``): ``lexicon.json`` (entries, parts, strokes, trigger words, styles,
source takes, rules, licence) and ``clips.npz`` (one float16 (T, 136) array per gesture and style, key
``"<name>.<style>"``). Reading them needs numpy and json only.

**A user's lexicon** (:func:`load_lexicon` on a folder with ``gestures.json``): name → ``clip`` (a BVH or
SMPL-X file in the folder, read with the same retargeting), ``triggers`` (non-empty), optional ``parts``
(default arms), optional ``stroke`` (seconds from the clip start; default: the frame where the wrists and head are
farthest from the clip's first pose, at its arrival), optional ``style`` (default neutral) and an optional
folder-level ``joint_map`` for a skeleton that is not detected automatically. User clips are not trimmed. A bad
entry raises a one-line :class:`UserError` naming the file and the field.
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.input_files import MIB
from gesturecast.models.motion.body_parts import PART_NAMES
from gesturecast.models.motion.motion import MOTION_FPS, Motion
from gesturecast.models.motion.motion_features import FEATURE_DIM, facing_yaw, rotate_planar
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.runtime.lexicon_checks import (
    MIN_CLIP_S,
    ClipArchive,
    built_fps,
    check_built_item,
    inside,
    read_json,
    user_clip_path,
)

FORMAT_VERSION = 1
LEXICON_FILE = "lexicon.json"
CLIPS_FILE = "clips.npz"
USER_MAPPING_FILE = "gestures.json"
MAX_MAPPING_BYTES = MIB  # a mapping file names a few dozen clips: 1 MiB is far more
MAX_LEXICON_BYTES = 64 * MIB  # lexicon.json / clips.npz of a built lexicon (the shipped one is well under 2 MB)
LICENSE_NOTE = ("Clips retargeted from the Bandai Namco Research Motion Dataset (datasets 1 and 2, "
                "https://github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset), CC BY-NC 4.0 "
                "(https://creativecommons.org/licenses/by-nc/4.0/): non-commercial use only.")
DEFAULT_STYLE = "neutral"

# trimming and stroke rules (module docstring)
ACTIVITY_JOINTS = ("LeftHand", "RightHand", "Head")
SMOOTH_FRAMES = 5
ACTIVE_FRACTION = 0.10
MARGIN_SECONDS = 0.2
STROKE_TOLERANCE = 0.05
REST_DROP = 0.25  # metres: wrists at least this far below the shoulders = arms down (hanging: about 0.5)
MAX_SECONDS = 4.0  # a longer clip has its hold (a held pose, repeated waving) shortened
KEEP_SECONDS = 1.0  # of the hold kept after the stroke
RELEASE_FRACTION = 0.5  # the hold ends at the last frame the stroke signal is above half its range
BLEND_FRAMES = 4  # cross-fade across a splice
SPLICE_TOLERANCE = 0.03  # metres: the most any joint may differ between the two 3-frame windows a splice joins
SPLICE_JOINTS = ("Spine", "Chest", "UpperChest", "Neck", "Head", "LeftShoulder", "LeftUpperArm", "LeftLowerArm",
                 "LeftHand", "RightShoulder", "RightUpperArm", "RightLowerArm", "RightHand")
STROKE_RULES = ("height", "bend", "reach")
HANDS = ("left", "right", "both", "either")
_SIDE = {"left": "Left", "right": "Right"}

# variants kept per gesture (build_lexicon)
MAX_VARIANTS = 5
STYLE_PREFERENCE = ("neutral", "happy", "sad", "old", "proud", "tired", "active")

_NAME = re.compile(r"^[a-z0-9][a-z0-9-]*$")


@dataclass(frozen=True)
class GestureSpec:
    """One lexicon gesture: where it comes from in the Bandai data and how its stroke is found."""

    name: str
    contents: tuple[str, ...]  # Bandai content labels (file-name field) it is built from
    parts: tuple[str, ...]  # body parts it moves (the model's ``body_parts``)
    rule: str  # stroke rule: height | bend | reach
    hand: str  # left | right | both | either
    triggers: tuple[str, ...]  # default English trigger words or phrases
    description: str


GESTURES: tuple[GestureSpec, ...] = (
    GestureSpec("wave", ("wave-both-hands",), ("arms",), "height", "both",
                ("hello", "hi", "hey", "welcome"), "waves both hands above the shoulders"),
    GestureSpec("wave-left", ("wave-left-hand",), ("arms",), "height", "left", (), "waves the left hand"),
    GestureSpec("wave-right", ("wave-right-hand",), ("arms",), "height", "right", (), "waves the right hand"),
    GestureSpec("raise-both", ("raise-up-both-hands",), ("arms",), "height", "both",
                ("hooray", "yay", "congratulations"), "raises both hands up"),
    GestureSpec("raise-left", ("raise-up-left-hand",), ("arms",), "height", "left", (), "raises the left hand"),
    GestureSpec("raise-right", ("raise-up-right-hand",), ("arms",), "height", "right", (), "raises the right hand"),
    GestureSpec("bow", ("bow",), ("arms", "torso", "legs"), "bend", "both", ("thank you", "thanks"),
                "bows from the waist, hands together in front"),
    GestureSpec("bye", ("bye", "byebye"), ("arms",), "height", "either", ("bye", "goodbye", "see you"),
                "waves goodbye"),
    GestureSpec("guide", ("guide",), ("arms", "torso"), "reach", "either", ("here", "there", "look at", "this"),
                "shows the way with an open arm, the chest turned with it"),
    GestureSpec("call", ("call",), ("arms", "torso", "legs"), "bend", "both", ("come on", "come here"),
                "calls out to someone: leans well forward, hands cupped at the mouth"),
    GestureSpec("respond", ("respond",), ("arms",), "height", "either", (), "raises a hand to answer"),
)
GESTURE_NAMES = tuple(spec.name for spec in GESTURES)


def gesture_spec(name: str) -> GestureSpec:
    for spec in GESTURES:
        if spec.name == name:
            return spec
    raise KeyError(name)


# ---------------------------------------------------------------------------------------------------------------
# motion analysis


def body_frame_positions(motion: Motion) -> np.ndarray:
    """(T, J, 3) joint positions relative to the hips in the hips' facing frame: x left, y up, z forward."""
    positions = motion.positions()
    relative = positions - positions[:, :1]
    yaw = facing_yaw(motion.rotations[:, 0])  # (T,)
    planar = rotate_planar(relative[..., [0, 2]], -yaw[:, None])  # (T, J, 2)
    return np.stack([planar[..., 0], relative[..., 1], planar[..., 1]], axis=-1)


def _moving_average(values: np.ndarray, frames: int) -> np.ndarray:
    if frames <= 1 or len(values) < 2:
        return values.astype(np.float64)
    padded = np.pad(values.astype(np.float64), frames // 2, mode="edge")
    return np.convolve(padded, np.ones(frames) / frames, mode="valid")[: len(values)]


def activity(body: np.ndarray, fps: float = MOTION_FPS) -> np.ndarray:
    """(T,) summed speed (m/s) of the wrists and head in the body frame, centred moving average."""
    joints = [CANONICAL.index(name) for name in ACTIVITY_JOINTS]
    speed = np.zeros(body.shape[0])
    if body.shape[0] > 1:
        step = np.linalg.norm(np.diff(body[:, joints], axis=0), axis=-1).sum(axis=-1) * fps  # (T-1,)
        speed[1:] = step
        speed[0] = step[0]
    return _moving_average(speed, SMOOTH_FRAMES)


def active_segment(level: np.ndarray, fps: float = MOTION_FPS, fraction: float = ACTIVE_FRACTION,
                   margin_seconds: float = MARGIN_SECONDS) -> tuple[int, int]:
    """``(start, stop)`` frames (stop exclusive) of the gesture: from the first to the last frame where ``level``
    is above ``fraction`` of its peak, widened by the margin within the take."""
    peak = float(level.max(initial=0.0))
    if len(level) == 0 or peak <= 0.0:
        return 0, len(level)
    above = np.flatnonzero(level > fraction * peak)
    margin = int(round(margin_seconds * fps))
    return max(0, int(above[0]) - margin), min(len(level), int(above[-1]) + 1 + margin)


def _hand_height(body: np.ndarray, side: str) -> np.ndarray:
    hand, shoulder = CANONICAL.index(f"{side}Hand"), CANONICAL.index(f"{side}UpperArm")
    return body[:, hand, 1] - body[:, shoulder, 1]


def _hand_reach(body: np.ndarray, side: str) -> np.ndarray:
    """Horizontal distance of the wrist from its shoulder (a hanging arm has almost none, a pointing arm most)."""
    hand, shoulder = CANONICAL.index(f"{side}Hand"), CANONICAL.index(f"{side}UpperArm")
    return np.linalg.norm(body[:, hand, [0, 2]] - body[:, shoulder, [0, 2]], axis=-1)


def stroke_signal(body: np.ndarray, rule: str, hand: str, segment: tuple[int, int] | None = None
                  ) -> tuple[np.ndarray, str]:
    """``(signal (T,), hand)``: the stroke rule's signal, and the hand it was read on (``either`` resolved to the
    hand whose signal varies most inside ``segment``; ``both`` and ``bend`` stay as they are)."""
    if rule == "bend":
        return body[:, CANONICAL.index("Head"), 2].astype(np.float64), hand
    if rule not in ("height", "reach"):
        raise ValueError(f"unknown stroke rule {rule!r}")
    read = _hand_height if rule == "height" else _hand_reach
    if hand == "both":
        return (read(body, "Left") + read(body, "Right")) / 2.0, hand
    if hand in _SIDE:
        return read(body, _SIDE[hand]), hand
    if hand != "either":
        raise ValueError(f"unknown hand {hand!r}")
    start, stop = segment if segment is not None else (0, body.shape[0])
    signals = {name: read(body, _SIDE[name]) for name in ("left", "right")}
    chosen = max(signals, key=lambda name: float(np.ptp(signals[name][start:stop])) if stop > start else 0.0)
    return signals[chosen], chosen


def stroke_frame(signal: np.ndarray, start: int = 0, stop: int | None = None,
                 tolerance: float = STROKE_TOLERANCE) -> int:
    """The frame (absolute) of the signal's peak inside ``[start, stop)``, at its arrival: the first frame within
    ``tolerance`` of the signal's range there below the peak."""
    stop = len(signal) if stop is None else stop
    window = signal[start:stop]
    if len(window) == 0:
        raise ValueError("empty segment")
    peak, low = float(window.max()), float(window.min())
    reached = np.flatnonzero(window >= peak - tolerance * (peak - low))
    return start + int(reached[0])


def pose_distance(body: np.ndarray, reference: int = 0) -> np.ndarray:
    """(T,) summed distance (m) of the wrists and head from their place at frame ``reference`` (body frame)."""
    joints = [CANONICAL.index(name) for name in ACTIVITY_JOINTS]
    return np.linalg.norm(body[:, joints] - body[reference, joints], axis=-1).sum(axis=-1)


@dataclass(frozen=True)
class GestureCut:
    """Where a take's gesture is: frames of the take (``stop`` exclusive) and the stroke (a frame of the take)."""

    start: int
    stop: int
    stroke: int
    hand: str
    rests: bool = True  # the clip's first and last frames have both hands down (:func:`at_rest`)
    removed: tuple[int, int] | None = None  # take frames [a, b) cut out of a long hold (:func:`shorten_hold`)

    @property
    def num_frames(self) -> int:
        """Frames of the clip (without the removed part of a long hold)."""
        removed = 0 if self.removed is None else self.removed[1] - self.removed[0]
        return self.stop - self.start - removed

    @property
    def stroke_in_clip(self) -> int:
        return self.stroke - self.start


def at_rest(body: np.ndarray, frame: int, drop: float = REST_DROP) -> bool:
    """Whether both wrists hang at least ``drop`` metres below their shoulders at ``frame`` (arms down)."""
    pose = body[frame][None]  # (1, J, 3)
    return bool(min(-_hand_height(pose, side)[0] for side in ("Left", "Right")) >= drop)


def _window_distance(points: np.ndarray, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The largest joint distance (m) between the 3-frame windows centred on ``first`` (A,) and ``second`` (B,):
    (A, B). Three frames compare the motion's direction too (a wave passing the same place the other way)."""
    worst = np.zeros((len(first), len(second)))
    for offset in (-1, 0, 1):
        a, b = points[first + offset], points[second + offset]  # (A, K, 3), (B, K, 3)
        worst = np.maximum(worst, np.linalg.norm(a[:, None] - b[None], axis=-1).max(axis=-1))
    return worst


def shorten_hold(body: np.ndarray, signal: np.ndarray, start: int, stop: int, stroke: int, fps: float = MOTION_FPS,
                 max_seconds: float = MAX_SECONDS, keep_seconds: float = KEEP_SECONDS) -> tuple[int, int] | None:
    """Take frames ``[a, b)`` to cut out of a clip longer than ``max_seconds`` (None: keep it whole).

    Only the hold is cut: ``a`` comes at least ``keep_seconds`` after the stroke and ``b`` no later than the
    release (the last frame where the stroke signal is above ``RELEASE_FRACTION`` of its range inside the clip),
    so the rise, the stroke, some of the hold and the whole retraction stay. Among the pairs that bring the clip to
    ``max_seconds`` or less (or, when none can, the one that removes the most), the one whose poses match best
    (:func:`_window_distance` of the torso, arm and head joints) is cut: a held pose or a wave at the same phase.
    Only joins where no joint differs by more than ``SPLICE_TOLERANCE`` are considered, so a hold that never
    repeats a pose is left whole."""
    max_frames = int(round(max_seconds * fps))
    if stop - start <= max_frames:
        return None
    window = signal[start:stop]
    low, peak = float(window.min()), float(window.max())
    release = start + int(np.flatnonzero(window >= low + RELEASE_FRACTION * (peak - low))[-1])
    first = stroke + int(round(keep_seconds * fps))
    if release - first < 2:
        return None
    points = body[:, [CANONICAL.index(name) for name in SPLICE_JOINTS]]
    cut_from = np.arange(max(first, start + 1), release)  # a: the first frame removed
    resume_at = np.arange(first + 1, min(release, stop - 2) + 1)  # b: the first frame kept after the cut
    if len(cut_from) == 0 or len(resume_at) == 0:
        return None
    distance = _window_distance(points, cut_from, resume_at)
    removed = resume_at[None, :] - cut_from[:, None]  # (A, B)
    matching = (removed > 0) & (distance <= SPLICE_TOLERANCE)
    if not matching.any():
        return None
    enough = matching & (removed >= (stop - start) - max_frames)
    if enough.any():  # the best-matching pair among those that bring the clip to max_seconds
        score = np.where(enough, distance, np.inf)
    else:  # none does: the pair that removes the most, the best-matching of those
        score = np.where(matching & (removed == removed[matching].max()), distance, np.inf)
    i, j = np.unravel_index(int(np.argmin(score)), score.shape)
    return int(cut_from[i]), int(resume_at[j])


def find_gesture(motion: Motion, spec: GestureSpec, max_seconds: float | None = MAX_SECONDS) -> GestureCut:
    """Trim a take to its gesture, mark the stroke and, for a clip longer than ``max_seconds`` (None: never), find
    the part of its hold to cut out (rules: module docstring)."""
    body = body_frame_positions(motion)
    start, stop = active_segment(activity(body, motion.fps), motion.fps)
    signal, hand = stroke_signal(body, spec.rule, spec.hand, (start, stop))
    rests = at_rest(body, start) and at_rest(body, stop - 1)
    stroke = stroke_frame(signal, start, stop)
    removed = None if max_seconds is None else shorten_hold(body, signal, start, stop, stroke, motion.fps,
                                                             max_seconds)
    return GestureCut(start, stop, stroke, hand, rests, removed)


def splice_features(features: np.ndarray, cut_from: int, resume_at: int, blend: int = BLEND_FRAMES) -> np.ndarray:
    """``features`` without frames ``[cut_from, resume_at)``, cross-faded linearly over ``blend`` frames around the
    join (6D rotations are re-orthonormalised when decoded, so a linear blend is a valid rotation)."""
    out = np.concatenate([features[:cut_from], features[resume_at:]]).astype(np.float64)
    half = blend // 2
    for i in range(-half, half):
        left, right = cut_from + i, resume_at + i
        if 0 <= left < len(features) and 0 <= right < len(features) and 0 <= left < len(out):
            weight = (i + half + 0.5) / (2 * half)
            out[left] = (1.0 - weight) * features[left] + weight * features[right]
    return out


# ---------------------------------------------------------------------------------------------------------------
# the lexicon in memory


@dataclass(frozen=True)
class GestureVariant:
    """One style of a gesture: its motion features (T, D) and stroke frame, and where it came from."""

    style: str
    features: np.ndarray  # (T, FEATURE_DIM), float16 as shipped, float32 for a user clip
    stroke_frame: int
    source: str
    fps: float = MOTION_FPS
    source_start: int = 0  # first frame of the clip in the source take
    hand: str = ""
    removed: tuple[int, int] | None = None  # source take frames [a, b) cut out of a long hold

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
    """A named gesture: the body parts it moves, its trigger words and one clip per style."""

    name: str
    parts: tuple[str, ...]
    triggers: tuple[str, ...]
    variants: tuple[GestureVariant, ...]
    description: str = ""

    @property
    def styles(self) -> tuple[str, ...]:
        return tuple(v.style for v in self.variants)

    def variant(self, style: str | None = None) -> GestureVariant:
        """The clip of ``style`` (any spelling of a style: "normal", "elderly"); the default (neutral, else the
        first) when the gesture has no such clip or ``style`` is None."""
        from gesturecast.models.generator.styles import canonical_style

        by_style = {v.style: v for v in self.variants}
        if style is not None:
            try:
                style = canonical_style(style)
            except UserError:  # a free-text style prompt, not a label
                style = None
        if style in by_style:
            return by_style[style]
        return by_style.get(DEFAULT_STYLE, self.variants[0])

    @property
    def duration(self) -> float:
        return self.variant().duration

    @property
    def stroke_time(self) -> float:
        return self.variant().stroke_time


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
                 "variants": [{"style": v.style, "duration": round(v.duration, 3), "stroke": round(v.stroke_time, 3),
                               "source": v.source} for v in e.variants]}
                for e in self.entries.values()]


# ---------------------------------------------------------------------------------------------------------------
# building from the Bandai takes

_BANDAI_TAKE = re.compile(r"^dataset-(\d+)_(?P<content>[^_]+)_(?P<style>[^_]+)_(?P<id>\d+)$")


@dataclass(frozen=True)
class CandidateTake:
    """A Bandai take of one lexicon gesture."""

    gesture: str
    style: str  # canonical
    name: str  # file stem
    path: Path


def bandai_gesture_takes(takes: Iterable, styles: Sequence[str] = STYLE_PREFERENCE) -> list[CandidateTake]:
    """The takes (``TakeSource`` s of :func:`bandai_takes`) whose content is a lexicon gesture and whose style is
    one of ``styles``."""
    by_content = {content: spec.name for spec in GESTURES for content in spec.contents}
    found = []
    for take in takes:
        match = _BANDAI_TAKE.match(take.name)
        if match is None or match["content"] not in by_content or take.style not in styles:
            continue
        found.append(CandidateTake(by_content[match["content"]], take.style, take.name, Path(take.motion_path)))
    return found


def select_candidates(candidates: Sequence[CandidateTake], per_style: int | None = None,
                      gestures: Sequence[str] | None = None) -> list[CandidateTake]:
    """The candidates of ``gestures`` (None: all), at most ``per_style`` per gesture and style (the first by name;
    None: all), in lexicon order."""
    chosen = []
    for spec in GESTURES:
        if gestures is not None and spec.name not in gestures:
            continue
        mine = sorted((c for c in candidates if c.gesture == spec.name), key=lambda c: c.name)
        for style in STYLE_PREFERENCE:
            chosen += [c for c in mine if c.style == style][:per_style]
    return chosen


def median_take(cuts: Sequence[tuple[CandidateTake, GestureCut]]) -> tuple[CandidateTake, GestureCut]:
    """The take whose trimmed length is the median (the lower of the two middle ones; ties by name)."""
    ordered = sorted(cuts, key=lambda item: (item[1].num_frames, item[0].name))
    return ordered[(len(ordered) - 1) // 2]


def trimmed_variant(motion: Motion, cut: GestureCut, style: str, source: str) -> GestureVariant:
    """The cut clip as a variant: faced forward from its own first frame, the removed part of a long hold spliced
    out, motion features in float16."""
    from gesturecast.models.motion.motion_features import face_forward, motion_to_features

    features = motion_to_features(face_forward(motion.slice(cut.start, cut.stop)))
    if cut.removed is not None:
        features = splice_features(features, cut.removed[0] - cut.start, cut.removed[1] - cut.start)
    return GestureVariant(style, features.astype(np.float16), cut.stroke_in_clip, source, motion.fps, cut.start,
                          cut.hand, cut.removed)


def build_lexicon(candidates: Sequence[CandidateTake], read: Callable[[Path], Motion],
                  progress: Callable[[Iterable], Iterable] | None = None,
                  max_variants: int = MAX_VARIANTS) -> Lexicon:
    """Read every candidate take, cut it, and keep per gesture the first ``max_variants`` styles of
    ``STYLE_PREFERENCE`` that have a take starting and ending at rest; per style the median-length one of those
    (module docstring). Styles left out for want of such a take are listed in ``metadata["skipped"]``.

    ``read``: path → canonical motion faced forward (``gesturecast data build``'s reader); ``progress`` wraps the
    iteration over the candidates (e.g. tqdm)."""
    cuts: dict[tuple[str, str], list[tuple[CandidateTake, GestureCut]]] = {}
    specs = {spec.name: spec for spec in GESTURES}
    for candidate in (progress or (lambda items: items))(list(candidates)):
        cut = find_gesture(read(candidate.path), specs[candidate.gesture])
        cuts.setdefault((candidate.gesture, candidate.style), []).append((candidate, cut))
    entries, skipped = {}, []
    for spec in GESTURES:
        variants: list[GestureVariant] = []
        for style in STYLE_PREFERENCE:
            if (spec.name, style) not in cuts or len(variants) >= max_variants:
                continue
            resting = [item for item in cuts[(spec.name, style)] if item[1].rests]
            if not resting:
                skipped.append(f"{spec.name}/{style}")
                continue
            candidate, cut = median_take(resting)
            variants.append(trimmed_variant(read(candidate.path), cut, style, candidate.name))  # read again: the
            # candidates' motions are not all kept in memory (a full build reads over a thousand takes)
        if variants:
            entries[spec.name] = GestureEntry(spec.name, spec.parts, spec.triggers, tuple(variants), spec.description)
    return Lexicon(entries, source="Bandai Namco Research Motion Dataset", license=LICENSE_NOTE,
                   metadata={"skipped": skipped})


# ---------------------------------------------------------------------------------------------------------------
# files


def _clip_key(name: str, style: str) -> str:
    return f"{name}.{style}"


def lexicon_json(lexicon: Lexicon) -> dict:
    return {
        "format_version": FORMAT_VERSION,
        "fps": MOTION_FPS,
        "feature_dim": FEATURE_DIM,
        "dtype": "float16",
        "clips": CLIPS_FILE,
        "source": lexicon.source,
        "license": lexicon.license,
        "rules": {"activity_joints": list(ACTIVITY_JOINTS), "smooth_frames": SMOOTH_FRAMES,
                  "active_fraction": ACTIVE_FRACTION, "margin_seconds": MARGIN_SECONDS,
                  "stroke_tolerance": STROKE_TOLERANCE, "max_seconds": MAX_SECONDS, "keep_seconds": KEEP_SECONDS,
                  "release_fraction": RELEASE_FRACTION, "splice_tolerance": SPLICE_TOLERANCE,
                  "blend_frames": BLEND_FRAMES, "rest_drop": REST_DROP, "style_preference": list(STYLE_PREFERENCE),
                  "variant": "per style, the median clip length among takes starting and ending at rest",
                  "docs": "docs/gestures.md"},
        "gestures": [
            {"name": e.name, "description": e.description, "parts": list(e.parts), "triggers": list(e.triggers),
             "duration": round(e.duration, 4), "stroke": round(e.stroke_time, 4), "styles": list(e.styles),
             "rule": _spec_rule(e.name),
             "variants": [{"style": v.style, "clip": _clip_key(e.name, v.style), "frames": v.num_frames,
                           "duration": round(v.duration, 4), "stroke_frame": v.stroke_frame,
                           "stroke": round(v.stroke_time, 4), "hand": v.hand, "source": v.source,
                           "source_start": v.source_start,
                           "removed": None if v.removed is None else list(v.removed)} for v in e.variants]}
            for e in lexicon.entries.values()],
    }


def _spec_rule(name: str) -> str:
    try:
        return gesture_spec(name).rule
    except KeyError:
        return "given"


def save_lexicon(lexicon: Lexicon, folder: Path) -> tuple[Path, Path]:
    """Write ``lexicon.json`` and ``clips.npz`` (float16, compressed) atomically; returns their paths."""
    from gesturecast.files import atomic_file, write_text_atomic

    folder = Path(folder)
    arrays = {_clip_key(e.name, v.style): np.ascontiguousarray(v.features, dtype=np.float16)
              for e in lexicon.entries.values() for v in e.variants}
    with atomic_file(folder / CLIPS_FILE, binary=True) as handle:
        np.savez_compressed(handle, **arrays)
    write_text_atomic(folder / LEXICON_FILE, json.dumps(lexicon_json(lexicon), indent=1) + "\n")
    return folder / LEXICON_FILE, folder / CLIPS_FILE


def _fail(path: Path, message: str) -> UserError:
    return UserError(f"{path}: {message}")


def read_built_lexicon(folder: Path) -> Lexicon:
    """A lexicon written by :func:`save_lexicon` (numpy + json only)."""
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
                                                   tuple(v["removed"]) if v.get("removed") else None))
                entries[item["name"]] = GestureEntry(item["name"], tuple(item["parts"]), tuple(item["triggers"]),
                                                     tuple(variants), item.get("description", ""))
    except (KeyError, TypeError, ValueError, zipfile.BadZipFile, OSError) as error:
        if isinstance(error, UserError):
            raise
        raise _fail(path, f"damaged gesture lexicon ({type(error).__name__}: {error})") from None
    meta = {k: v for k, v in raw.items() if k not in ("gestures",)}
    return Lexicon(entries, source=str(raw.get("source", "")), license=str(raw.get("license", "")), metadata=meta)


def _default_reader(joint_map: Path | None) -> Callable[[Path], Motion]:
    def read(path: Path) -> Motion:
        from gesturecast.models.motion.motion_features import face_forward
        from gesturecast.models.motion.retarget import load_motion_file

        return face_forward(load_motion_file(path, joint_map))
    return read


def _user_entry(name: str, item: object, folder: Path, mapping: Path,
                read: Callable[[Path], Motion]) -> GestureEntry:
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


def read_user_lexicon(folder: Path, read: Callable[[Path], Motion] | None = None) -> Lexicon:
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
