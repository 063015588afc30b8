"""Building the gesture lexicon from the labelled Bandai Namco takes (offline: ``gesturecast gestures build``).

The live runtime reads what this writes (:mod:`gesturecast.realtime.gestures.lexicon`: the data types,
``load_lexicon``); nothing live imports this module. Numpy only (no torch).

**Sources** (:data:`GESTURES`): Bandai Namco Research Motion Dataset 1 (``bow``, ``bye`` and ``byebye`` (our
``hand-up``), ``guide``,
``call``, ``respond``; 15 styles, ``call`` and ``respond`` in normal only) and the gesture subset of dataset 2
(``wave-*-hand(s)``, ``raise-up-*-hand(s)``; 7 styles, 50 to 200 takes per gesture and style). Every take is read
and retargeted exactly as ``gesturecast data build`` reads it (:func:`read_take`: ``load_motion_file`` then
``face_forward``), and the shipped clips are its motion features (:func:`motion_to_features`, D = 136, 30 fps).

**Body frame.** Every rule reads joint positions in the hips' facing frame (:func:`body_frame_positions`,
:mod:`gesturecast.realtime.gestures.strokes`), so walking or turning does not count as gesturing.

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
some dataset-1 takes start or end mid-gesture); per style up to ``MAX_TAKES`` (3) of those takes
(:func:`spread_takes`): first the one whose trimmed length is the median (a typical performance, the style's
default), then, among the typical ones (trimmed length within the interquartile range, ``TYPICAL_QUANTILES``), in
turn the take whose pose around its stroke (the torso, arm and head joints over ``SPREAD_SECONDS``, 1 s, on each
side of the stroke, in the body frame) is farthest from the nearest take already kept. So a stream's performances
play recordings that look different where the data has several (dataset 2: 30 to 200 per style; dataset 1: one or
two), none of them the shortest or the longest.

**Files** (:func:`save_lexicon`): ``lexicon.json`` (entries, parts, strokes, trigger words, styles, source takes,
rules, licence) and ``clips.npz`` (one float16 (T, 136) array per gesture, style and take, key
``"<name>.<style>.<take>"``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.realtime.gestures.lexicon import (
    CLIPS_FILE,
    FORMAT_VERSION,
    LEXICON_FILE,
    GestureEntry,
    GestureVariant,
    Lexicon,
)
from gesturecast.realtime.gestures.strokes import (
    ACTIVITY_JOINTS,
    STROKE_TOLERANCE,
    body_frame_positions,
    stroke_frame,
)

LICENSE_NOTE = ("Clips retargeted from the Bandai Namco Research Motion Dataset (datasets 1 and 2, "
                "https://github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset), CC BY-NC 4.0 "
                "(https://creativecommons.org/licenses/by-nc/4.0/): non-commercial use only.")

# trimming and stroke rules (module docstring)
SMOOTH_FRAMES = 5
ACTIVE_FRACTION = 0.10
MARGIN_SECONDS = 0.2
REST_DROP = 0.25  # metres: wrists at least this far below the shoulders = arms down (hanging: about 0.5)
MAX_SECONDS = 4.0  # a longer clip has its hold (a held pose, repeated waving) shortened
KEEP_SECONDS = 1.0  # of the hold kept after the stroke
RELEASE_FRACTION = 0.5  # the hold ends at the last frame the stroke signal is above half its range
BLEND_FRAMES = 4  # cross-fade across a splice
SPLICE_TOLERANCE = 0.03  # metres: the most any joint may differ between the two 3-frame windows a splice joins
SPLICE_JOINTS = ("Spine", "Chest", "UpperChest", "Neck", "Head", "LeftShoulder", "LeftUpperArm", "LeftLowerArm",
                 "LeftHand", "RightShoulder", "RightUpperArm", "RightLowerArm", "RightHand")
_SIDE = {"left": "Left", "right": "Right"}

# variants kept per gesture (build_lexicon)
MAX_VARIANTS = 5
MAX_TAKES = 3  # takes kept per gesture and style
TYPICAL_QUANTILES = (0.25, 0.75)  # the takes after the first come from this range of trimmed lengths
SPREAD_SECONDS = 1.0  # takes are compared over this long on each side of their strokes
STYLE_PREFERENCE = ("neutral", "happy", "sad", "old", "proud", "tired", "active")


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
    GestureSpec("wave-right", ("wave-right-hand",), ("arms",), "height", "right", ("bye", "goodbye", "see you"),
                "waves the right hand"),
    GestureSpec("raise-both", ("raise-up-both-hands",), ("arms",), "height", "both",
                ("hooray", "yay", "congratulations"), "raises both hands up"),
    GestureSpec("raise-left", ("raise-up-left-hand",), ("arms",), "height", "left", (), "raises the left hand"),
    GestureSpec("raise-right", ("raise-up-right-hand",), ("arms",), "height", "right", (), "raises the right hand"),
    GestureSpec("bow", ("bow",), ("arms", "torso", "legs"), "bend", "both", ("thank you", "thanks"),
                "bows from the waist, hands together in front"),
    GestureSpec("hand-up", ("bye", "byebye"), ("arms",), "height", "either", (),
                "holds a hand up at shoulder height"),  # Bandai's "bye": the hand is held, not waved
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


@dataclass(frozen=True)
class GestureCut:
    """Where a take's gesture is: frames of the take (``stop`` exclusive) and the stroke (a frame of the take)."""

    start: int
    stop: int
    stroke: int
    hand: str
    rests: bool = True  # the clip's first and last frames have both hands down (:func:`at_rest`)
    removed: tuple[int, int] | None = None  # take frames [a, b) cut out of a long hold (:func:`shorten_hold`)
    around_stroke: np.ndarray | None = field(default=None, compare=False, repr=False)  # (F, K, 3): :func:`stroke_pose`

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


def stroke_pose(body: np.ndarray, start: int, stop: int, stroke: int, fps: float = MOTION_FPS,
                seconds: float = SPREAD_SECONDS) -> np.ndarray:
    """(F, K, 3) body-frame positions of the torso, arm and head joints (``SPLICE_JOINTS``) from ``seconds`` before
    to ``seconds`` after the stroke, F = 2 * seconds * fps frames, the clip's first or last frame repeated where it
    ends sooner (takes of one gesture compare frame by frame, aligned at their strokes)."""
    half = int(round(seconds * fps))
    frames = np.clip(np.arange(stroke - half, stroke + half), start, stop - 1)  # (F,)
    return body[frames][:, [CANONICAL.index(name) for name in SPLICE_JOINTS]]


def find_gesture(motion: SkeletonMotion, spec: GestureSpec, max_seconds: float | None = MAX_SECONDS) -> GestureCut:
    """Trim a take to its gesture, mark the stroke and, for a clip longer than ``max_seconds`` (None: never), find
    the part of its hold to cut out; keep its pose around the stroke (rules: module docstring)."""
    body = body_frame_positions(motion)
    start, stop = active_segment(activity(body, motion.fps), motion.fps)
    signal, hand = stroke_signal(body, spec.rule, spec.hand, (start, stop))
    rests = at_rest(body, start) and at_rest(body, stop - 1)
    stroke = stroke_frame(signal, start, stop)
    removed = None if max_seconds is None else shorten_hold(body, signal, start, stop, stroke, motion.fps,
                                                             max_seconds)
    return GestureCut(start, stop, stroke, hand, rests, removed, stroke_pose(body, start, stop, stroke, motion.fps))


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


def pose_difference(first: GestureCut, second: GestureCut) -> float:
    """Mean joint distance (m) between two takes' poses around their strokes (:func:`stroke_pose`)."""
    return float(np.linalg.norm(first.around_stroke - second.around_stroke, axis=-1).mean())


def spread_takes(cuts: Sequence[tuple[CandidateTake, GestureCut]], count: int = MAX_TAKES
                 ) -> list[tuple[CandidateTake, GestureCut]]:
    """Up to ``count`` of the takes: the one whose trimmed length is the median (the lower of the two middle ones;
    lengths tied by name), then in turn the typical take (trimmed length within the ``TYPICAL_QUANTILES`` of the
    lengths; every take when there are no more than ``count``) whose pose around its stroke is farthest from the
    nearest take kept (:func:`pose_difference`; ties: the shorter)."""
    ordered = sorted(cuts, key=lambda item: (item[1].num_frames, item[0].name))
    last = len(ordered) - 1
    low, high = (int(q * last) for q in TYPICAL_QUANTILES) if len(ordered) > count else (0, last)
    kept = [last // 2]
    typical = [i for i in range(low, high + 1) if i != last // 2]
    while typical and len(kept) < count:
        farthest = max(typical, key=lambda i: min(pose_difference(ordered[i][1], ordered[k][1]) for k in kept))
        kept.append(farthest)
        typical.remove(farthest)
    return [ordered[i] for i in kept]


def trimmed_variant(motion: SkeletonMotion, cut: GestureCut, style: str, source: str, take: int = 0) -> GestureVariant:
    """The cut clip as take ``take`` of ``style``: faced forward from its own first frame, the removed part of a long
    hold spliced out, motion features in float16."""
    from gesturecast.models.motion.motion_features import face_forward, motion_to_features

    features = motion_to_features(face_forward(motion.slice(cut.start, cut.stop)))
    if cut.removed is not None:
        features = splice_features(features, cut.removed[0] - cut.start, cut.removed[1] - cut.start)
    return GestureVariant(style, features.astype(np.float16), cut.stroke_in_clip, source, motion.fps, cut.start,
                          cut.hand, cut.removed, take)


def build_lexicon(candidates: Sequence[CandidateTake], read: Callable[[Path], SkeletonMotion],
                  progress: Callable[[Iterable], Iterable] | None = None,
                  max_variants: int = MAX_VARIANTS, max_takes: int = MAX_TAKES) -> Lexicon:
    """Read every candidate take, cut it, and keep per gesture the first ``max_variants`` styles of
    ``STYLE_PREFERENCE`` that have a take starting and ending at rest; per style up to ``max_takes`` of those,
    spread over their lengths (:func:`spread_takes`). Styles left out for want of such a take are listed in
    ``metadata["skipped"]``.

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
            if (spec.name, style) not in cuts or len({v.style for v in variants}) >= max_variants:
                continue
            resting = [item for item in cuts[(spec.name, style)] if item[1].rests]
            if not resting:
                skipped.append(f"{spec.name}/{style}")
                continue
            variants += [trimmed_variant(read(candidate.path), cut, style, candidate.name, take)  # read again: the
                         # candidates' motions are not all kept in memory (a full build reads over a thousand takes)
                         for take, (candidate, cut) in enumerate(spread_takes(resting, max_takes))]
        if variants:
            entries[spec.name] = GestureEntry(spec.name, spec.parts, spec.triggers, tuple(variants), spec.description)
    return Lexicon(entries, source="Bandai Namco Research Motion Dataset", license=LICENSE_NOTE,
                   metadata={"skipped": skipped})


# ---------------------------------------------------------------------------------------------------------------
# files


def _clip_key(name: str, variant: GestureVariant) -> str:
    return f"{name}.{variant.style}.{variant.take}"


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
                  "max_takes": MAX_TAKES, "typical_quantiles": list(TYPICAL_QUANTILES),
                  "spread_seconds": SPREAD_SECONDS,
                  "variant": "per style, among the takes starting and ending at rest: the median clip length, then "
                             "the typical-length take whose pose around the stroke is farthest from those kept",
                  "docs": "docs/gestures.md"},
        "gestures": [
            {"name": e.name, "description": e.description, "parts": list(e.parts), "triggers": list(e.triggers),
             "duration": round(e.duration, 4), "stroke": round(e.stroke_time, 4), "styles": list(e.styles),
             "rule": _spec_rule(e.name),
             "variants": [{"style": v.style, "take": v.take, "clip": _clip_key(e.name, v), "frames": v.num_frames,
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
    arrays = {_clip_key(e.name, v): np.ascontiguousarray(v.features, dtype=np.float16)
              for e in lexicon.entries.values() for v in e.variants}
    with atomic_file(folder / CLIPS_FILE, binary=True) as handle:
        np.savez_compressed(handle, **arrays)
    write_text_atomic(folder / LEXICON_FILE, json.dumps(lexicon_json(lexicon), indent=1) + "\n")
    return folder / LEXICON_FILE, folder / CLIPS_FILE
