"""Gesture cues carried out by the generator: a lexicon clip's body-part latents imposed while denoising its window.

A :class:`Cue` asks for a gesture's stroke at a stream time (a word's start, a button press). :class:`CuePlan`
places it on the latent grid so that the clip's stroke latent covers that time. While a placed clip covers latent
``i``, :meth:`CuePlan.imposition` gives the clip's latent ``k = i − first`` and a weight per latent channel: the
channels of the parts the gesture moves (arms for a wave, torso and arms for a bow), ramped up over the played
part's first latents (:data:`RAMP_LATENTS`) and down over its last ones. The generator pulls its x̂0 prediction
toward that latent at every sampler step (inpainting those channels, as motion-diffusion models inpaint joints), so
the approach and the return blend with what it generates from the context, and the parts not gesturing keep
following the speech. The decoded poses of those parts are then blended toward the clip's own joint rotations with
the same ramp (per frame): the VQ decoder alone flattens some gestures (a bye's raised hand came out 0.2 m lower
than recorded), and the blend keeps their shape while the latents keep the neighbouring motion consistent with it.

**Nothing is lost in silence.** Every cue ends in a :class:`CueOutcome`, counted in :attr:`CuePlan.counts`:

- ``on time``: the stroke latent covers the word;
- ``late``: the cue came after its window began; the clip's opening is skipped (a quicker approach over
  :data:`BLEND_LATENTS` latents) so the stroke lands as soon after the word as that allows, at most
  :data:`MAX_LATE_S` after it (later, the cue is dropped: a gesture seconds after its word means nothing);
- ``blended``: it meets gestures playing on a shared body part (every placement of theirs: a bow shared with a
  wave is two). A later gesture with parts of its own (a bow's torso after a wave) plays those on time alongside the
  earlier ones and takes the shared parts over once they have held their strokes (:data:`HOLD_LATENTS`). Otherwise,
  where the earlier ones have held their strokes that long, their holds are cut short and their whole returns moved
  earlier, to end where the later one's approach begins (a wave lowers the hands before a cheer:
  :attr:`Placement.skip`, the clip's release known from :func:`gesturecast.realtime.gestures.strokes.release_frame`);
  else their returns are cut short and cross-fade over :data:`BLEND_LATENTS` latents into the later one's approach,
  the later stroke moved at most :data:`MAX_DEFER_S` after its word when the strokes are closer than the cross-fade.
  Either way an earlier gesture gives way as a whole (a bow's legs end with the arms and torso a wave takes over);
- ``merged``: the same gesture is already playing over the word and holds on after it (a "hello" right after a
  "hi"); one already returning is played again, after it;
- ``dropped``: none of these fits (logged, counted).

Every outcome is counted; those not on time are logged, a flood (a cue per OSC packet or per word) at most one line
per 5 s for the dropped ones and one for the others, with the count of those not logged
(:class:`~gesturecast.log_throttle.ThrottledLog`).

A gesture may have several performances (:mod:`gesturecast.realtime.gestures.clips`: takes, hand, tempo and
amplitude drawn from the seed); the plan plays them in turn. The plan is deterministic in stream time, so streaming and
offline runs with the same cues give the same poses.

The placements are kept in order of their first latent, so placing a cue and imposing a latent look only at the
clips that can overlap it (a clip is at most the longest performance): their cost does not grow with the number of
cues waiting. A plan holds at most :data:`MAX_PLACEMENTS` of them (:class:`CueRefused` beyond), and
:meth:`CuePlan.check_ahead` refuses cue times more than :data:`MAX_AHEAD_S` ahead of the stream (live doors).
"""

from __future__ import annotations

import bisect
import logging
import math
from collections import Counter, deque
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from gesturecast.controls import MAX_STREAM_SECONDS
from gesturecast.errors import UserError
from gesturecast.log_throttle import ThrottledLog
from gesturecast.realtime.gestures.reattach import body_frame_roots, placed_roots, reattach

logger = logging.getLogger(__name__)

RAMP_LATENTS = 4  # latents over which the imposition weight rises to 1 (and falls back) at each end of a clip
BLEND_LATENTS = 3  # the cross-fade of two gestures that meet, and the quickest approach of a late one (400 ms)
HOLD_LATENTS = 6  # a gesture holds its stroke this long (800 ms) before a later one takes over parts it shares
MAX_DEFER_S = 0.6  # a cue's stroke is moved at most this much after its word to fit after a playing gesture
MAX_LATE_S = 1.0  # a cue whose stroke cannot come within this of its time (words that came too late) is dropped
MAX_OUTCOMES = 256  # recent outcomes kept for reports (the counts cover the whole stream)
STATUSES = ("on time", "late", "blended", "merged", "dropped")
CONTROL_SOURCE = "control"  # a cue from a gesture control (button, OSC): played as soon as it can
MAX_PLACEMENTS = 20_000  # placed cues still to come (a transcript's hours of gestures); beyond: CueRefused
MAX_AHEAD_S = 300.0  # words sent live (a TTS reply) are at most this far ahead of the stream


class CueRefused(UserError):
    """A cue the plan does not keep: too far ahead of the stream, or the plan already holds its most."""


@dataclass(frozen=True)
class Cue:
    """Perform ``gesture`` with its stroke at stream time ``time`` (s); ``source`` says why (e.g. the word)."""

    gesture: str
    time: float
    source: str = ""


@dataclass(frozen=True)
class GestureClip:
    """A lexicon clip in one model's latent space.

    latents: (N, C) normalised latents of the clip (the model's VQ encoder of its motion features).
    channels: (C,) bool, the latent channels of the body parts the gesture moves.
    stroke_latent: index of the latent that holds the stroke.
    features: (N·d, D) the clip's motion features (denormalised), d frames per latent.
    columns: (D,) bool, the feature columns of the moving parts' joint rotations (never the root's travel).
    roots: the first imposed joint of each chain under generated parents (an arms-only clip's shoulders, an arms
    and torso clip's spine): its feature columns, the joints between it and the hips, and its (N·d, 4) rotation in
    the body frame (:mod:`gesturecast.realtime.gestures.reattach`).
    release_latent: the last latent of the clip's hold (after it the wrists and head only come back,
    :func:`gesturecast.realtime.gestures.strokes.release_frame`), or -1 when not known (its return is never moved).
    """

    name: str
    latents: np.ndarray
    channels: np.ndarray
    stroke_latent: int
    features: np.ndarray
    columns: np.ndarray
    roots: tuple = ()  # (columns, joints above, (N·d, 4) body-frame rotation) per re-attached joint (reattach)
    release_latent: int = -1  # the last latent of its hold, where its return begins (-1: not known)

    @property
    def num_latents(self) -> int:
        return self.latents.shape[0]

    @property
    def frames_per_latent(self) -> int:
        return self.features.shape[0] // self.num_latents


@dataclass(frozen=True)
class Placement:
    """A cue placed on the latent grid: clip latent ``k`` belongs to stream latent ``first + k`` (``first + k − skip``
    where ``skip`` latents of its hold are left out: its return moved earlier); the stream latents ``start`` …
    ``stop`` (inclusive) play it, ramped over ``ramp_in`` latents after ``start`` and ``ramp_out`` before ``stop``."""

    cue: Cue
    clip: GestureClip
    first: int
    late_s: float  # how much later than asked the stroke lands (0 when the cue came early enough)
    start: int
    stop: int
    ramp_in: int = RAMP_LATENTS
    ramp_out: int = RAMP_LATENTS
    skip: int = 0

    @property
    def stroke(self) -> int:
        """The stream latent of the stroke."""
        return self.first + self.clip.stroke_latent

    @property
    def last(self) -> int:
        return self.stop

    @property
    def whole(self) -> bool:
        """Whether it plays to the clip's end as placed (its return neither cut nor moved)."""
        return self.skip == 0 and self.stop == self.first + self.clip.num_latents - 1

    def clip_latent(self, latent: int) -> int:
        """The clip latent that stream latent ``latent`` plays."""
        return latent - self.first + self.skip

    def covers(self, latent: int) -> bool:
        return self.start <= latent <= self.stop

    def weight(self, latent: int) -> float:
        """Imposition weight on stream latent ``latent`` (0 outside the played span)."""
        if not self.covers(latent):
            return 0.0
        return min(1.0, (latent - self.start + 1) / (self.ramp_in + 1), (self.stop - latent + 1) / (self.ramp_out + 1))

    def holds(self, latent: int) -> bool:
        """Whether the gesture is held on stream latent ``latent``: played at weight 0.5 or more and, where the
        clip's release is known, for :data:`BLEND_LATENTS` more before its return."""
        release = self.clip.release_latent
        return self.weight(latent) >= 0.5 and (release < 0 or self.clip_latent(latent) + BLEND_LATENTS <= release)

    def frame_weights(self, latent: int) -> np.ndarray:
        """(d,) pose-blend weights of the frames of stream latent ``latent`` (the same ramps, per frame)."""
        d = self.clip.frames_per_latent
        frames = np.arange(latent * d, (latent + 1) * d)  # (d,) stream frames
        rise = (frames - self.start * d + 1) / (self.ramp_in * d + 1)
        fall = ((self.stop + 1) * d - frames) / (self.ramp_out * d + 1)
        return np.clip(np.minimum(rise, fall), 0.0, 1.0).astype(np.float32)

    def overlaps(self, other: Placement) -> bool:
        """Whether the two play on a shared body part at the same time."""
        return (self.start <= other.stop and other.start <= self.stop
                and bool((self.clip.channels & other.clip.channels).any()))


def part_clip(clip: GestureClip, channels: np.ndarray, columns: np.ndarray) -> GestureClip:
    """``clip`` on the latent ``channels`` and feature ``columns`` it moves among those given (bool masks), its
    chains re-attached where their parents are no longer its own (a guide's arms without its torso)."""
    kept = clip.columns & columns
    return replace(clip, channels=clip.channels & channels, columns=kept,
                   roots=tuple(body_frame_roots(clip.features, kept)))


def ramp_weight(k: int, length: int, ramp: int = RAMP_LATENTS) -> float:
    """Imposition weight of clip latent ``k`` of ``length``: rises over the first ``ramp``, falls over the last."""
    return min(1.0, (k + 1) / (ramp + 1), (length - k) / (ramp + 1))


@dataclass(frozen=True)
class CueOutcome:
    """What became of a cue: a status of :data:`STATUSES`, when its stroke plays (None when dropped), and why."""

    cue: Cue
    status: str
    stroke_time: float | None
    note: str = ""

    def describe(self) -> str:
        """One line for logs and control acks."""
        what = f"gesture {self.cue.gesture} ({self.cue.source or 'cue'})"
        if self.stroke_time is None:
            return f"{what} dropped: {self.note}"
        delay = (self.stroke_time - self.cue.time) * 1e3
        since = "the press" if self.cue.source == CONTROL_SOURCE else "its time"
        when = f"on {since}" if delay <= 0 else f"{delay:.0f} ms after {since}"
        note = f": {self.note}" if self.note else ""
        return f"{what} {self.status}, stroke at {self.stroke_time:.2f} s ({when}){note}"


def played(outcomes: list[CueOutcome]) -> int:
    """How many of ``outcomes`` play (all but the dropped)."""
    return sum(outcome.stroke_time is not None for outcome in outcomes)


@dataclass
class Imposition:
    """What the placed clips ask of one latent: its latent (C,) target and weights, the decoded poses' (d, D)
    target features and per-frame weights, and the gesture names ("wave", "wave+bow" while they cross-fade)."""

    target: np.ndarray
    weights: np.ndarray
    pose: np.ndarray
    pose_weights: np.ndarray
    names: str
    roots: list = field(default_factory=list)  # PlacedRoot of each playing clip's re-attached joints (reattach)

    @classmethod
    def of(cls, placements: list[Placement], latent: int) -> Imposition:
        """The weighted mean of the clips covering ``latent`` on their channels and columns (weights summed, at
        most 1: two gestures cross-fading hand over to each other)."""
        clip = placements[0].clip
        d, dim, channels = clip.frames_per_latent, clip.features.shape[1], clip.latents.shape[1]
        target, weights = np.zeros(channels, np.float32), np.zeros(channels, np.float32)
        pose, pose_weights = np.zeros((d, dim), np.float32), np.zeros((d, dim), np.float32)
        for placement in placements:
            k, c = placement.clip_latent(latent), placement.clip
            w = placement.weight(latent)
            target[c.channels] += w * c.latents[k, c.channels]
            weights[c.channels] += w
            frame_w = placement.frame_weights(latent)[:, None]  # (d, 1)
            pose[:, c.columns] += frame_w * c.features[k * d:(k + 1) * d][:, c.columns]
            pose_weights[:, c.columns] += frame_w
        target /= np.maximum(weights, 1e-6)
        pose /= np.maximum(pose_weights, 1e-6)
        roots = [root for p in placements for root in placed_roots(
            p.clip.roots, p.clip.features, slice(p.clip_latent(latent) * d, (p.clip_latent(latent) + 1) * d),
            p.frame_weights(latent)[:, None], pose_weights)]
        return cls(target, np.minimum(weights, 1.0), pose, np.minimum(pose_weights, 1.0),
                   "+".join(dict.fromkeys(p.cue.gesture for p in placements)), roots)

    def blend(self, features: np.ndarray) -> np.ndarray:
        """(d, D) decoded features pulled toward the clips' joint rotations, the first imposed joint of each chain
        re-attached under its parents as blended (:mod:`gesturecast.realtime.gestures.reattach`)."""
        return reattach(features, self.pose, self.pose_weights, self.roots)


class CuePlan:
    """Placed cues of one stream (see the module docstring); ``seconds_per_latent`` = d / fps."""

    def __init__(self, clips: Mapping[str, GestureClip], seconds_per_latent: float,
                 performances: Mapping[str, Sequence[GestureClip]] | None = None,
                 max_placements: int = MAX_PLACEMENTS) -> None:
        self.clips = dict(clips)
        self.performances = {name: tuple(p) for name, p in (performances or {}).items() if p}
        self.plays: Counter[str] = Counter()  # cues placed per gesture: the next performance to play
        self.seconds_per_latent = seconds_per_latent
        self.max_placements = max_placements
        every = [*self.clips.values(), *(c for versions in self.performances.values() for c in versions)]
        self.longest = max((clip.num_latents for clip in every), default=1)  # latents a placement can span
        self.placements: list[Placement] = []  # in order of their first latent
        self.counts: Counter[str] = Counter()  # outcomes by status, over the whole stream
        self.outcomes: deque[CueOutcome] = deque(maxlen=MAX_OUTCOMES)
        self.max_defer = round(MAX_DEFER_S / seconds_per_latent)  # latents
        self._drop_log, self._note_log = ThrottledLog(logger), ThrottledLog(logger)  # a cue flood: a line per interval

    @property
    def dropped(self) -> int:
        return self.counts["dropped"]

    def check(self, gesture: str) -> GestureClip:
        """The clip of ``gesture``; a one-line UserError naming the known ones otherwise."""
        if gesture not in self.clips:
            raise UserError(f"unknown gesture {gesture!r}; known: {', '.join(sorted(self.clips))}")
        return self.clips[gesture]

    def check_ahead(self, times: Iterable[float], next_latent: int, limit_s: float = MAX_AHEAD_S) -> None:
        """CueRefused for a cue time more than ``limit_s`` ahead of ``next_latent`` (the first latent not generated
        yet), or when the plan is full: what a live door checks before it queues words or a gesture."""
        now = next_latent * self.seconds_per_latent
        latest = max(times, default=now)
        if latest - now > limit_s:
            raise CueRefused(f"a word at {latest:.6g} s is {latest - now:.6g} s ahead of the stream (at {now:.1f} s); "
                             f"send words at most {limit_s:.0f} s ahead")
        self._check_room()

    def _check_room(self) -> None:
        if len(self.placements) >= self.max_placements:
            raise CueRefused(f"the stream already holds {len(self.placements)} gestures to come (at most "
                             f"{self.max_placements}); send more once some have played")

    def place(self, cue: Cue, next_latent: int) -> CueOutcome:
        """Place ``cue`` no earlier than ``next_latent`` (the first latent not generated yet): on time, late,
        blended with a playing gesture, merged into the same one, or dropped; logged unless on time (a flood
        throttled), and counted.
        CueRefused for a time that is no stream time, or when the plan is full."""
        if not math.isfinite(cue.time) or cue.time > MAX_STREAM_SECONDS:
            raise CueRefused(f"gesture {cue.gesture} at {cue.time!r} s: not a stream time "
                             f"(at most {MAX_STREAM_SECONDS:g})")
        self._check_room()
        clip = self._performance(self.check(cue.gesture))
        wanted = math.floor(cue.time / self.seconds_per_latent)  # the stroke latent that covers the word
        merged = next((p for p in self._covering(wanted) if p.cue.gesture == cue.gesture and p.holds(wanted)), None)
        if merged is not None:
            return self._record(CueOutcome(cue, "merged", self._time(merged.stroke), f"into the {cue.gesture} playing"))
        placement = self._fresh(cue, clip, wanted, next_latent)
        if placement.late_s > MAX_LATE_S and cue.source != CONTROL_SOURCE:
            return self._drop(cue, f"its words came {placement.late_s:.1f} s too late for the stroke to be near them")
        conflicts = self._overlapping(placement)
        if conflicts:
            return self._blend(placement, conflicts, next_latent)
        if cue.source == CONTROL_SOURCE:  # a button press: as soon as it can, never "late"
            return self._accept(placement, "on time", "as soon as the look-ahead allows")
        return self._accept(placement, "late" if placement.late_s > 0 else "on time", "")

    def _performance(self, clip: GestureClip) -> GestureClip:
        """The gesture's next performance in turn (its clip when it has none): two plays in a row differ."""
        versions = self.performances.get(clip.name)
        if not versions:
            return clip
        self.plays[clip.name] += 1
        return versions[(self.plays[clip.name] - 1) % len(versions)]

    def _time(self, latent: int) -> float:
        return latent * self.seconds_per_latent

    def _fresh(self, cue: Cue, clip: GestureClip, stroke: int, next_latent: int) -> Placement:
        """The whole clip with its stroke on ``stroke``; a cue too late for its approach skips the clip's opening and
        approaches over :data:`BLEND_LATENTS`, its stroke moved later only as far as that needs."""
        stroke = max(stroke, next_latent + BLEND_LATENTS)
        first = stroke - clip.stroke_latent
        start = max(first, next_latent)
        late = max(0.0, self._time(stroke) - cue.time)
        return Placement(cue, clip, first, late, start, first + clip.num_latents - 1,
                         ramp_in=max(1, min(RAMP_LATENTS, stroke - start)))

    def _blend(self, placement: Placement, conflicts: list[Placement], next_latent: int) -> CueOutcome:
        """Fit ``placement`` after the gestures it meets (every placement of theirs, each part of a shared one),
        cutting their holds or returns short from ``next_latent`` on (the first latent not generated yet), or drop
        it."""
        earlier = max(conflicts, key=lambda p: p.stroke)
        if earlier.stroke > placement.stroke:
            return self._drop(placement.cue, f"{earlier.cue.gesture} ({earlier.cue.source}) holds the same body "
                              f"parts around the word")
        busy = np.logical_or.reduce([p.clip.channels for p in conflicts])
        if (placement.clip.channels & ~busy).any():
            return self._share(placement, conflicts, earlier, busy)
        conflicts = self._with_siblings(conflicts, placement.start)
        start = max(placement.start, earlier.stroke + 1)
        returns = self._returns(conflicts, start, next_latent) if start == placement.first else None
        later = placement if returns else self._deferred(placement, start)
        if later is None:
            return self._drop(placement.cue, f"{earlier.cue.gesture} ({earlier.cue.source}) plays too close before it")
        if not self._hand_over(conflicts, later.start, [later], returns):
            return self._drop(placement.cue, "the gestures around it leave no room")
        self._insert(later)
        cut = "hold" if returns else "return"
        return self._record(CueOutcome(later.cue, "blended", self._time(later.stroke),
                                       f"after the {_names(conflicts)}, whose {cut} is cut short"))

    def _with_siblings(self, conflicts: list[Placement], latent: int) -> list[Placement]:
        """``conflicts`` and the other placements of their cues still playing on ``latent`` or after (a bow's legs
        beside the arms and torso a wave takes over): a gesture gives way as a whole."""
        nearby = self._starting_within(latent - self.longest + 1, latent + self.longest)
        return conflicts + [p for p in nearby if p.stop >= latent and any(p.cue == c.cue for c in conflicts)
                            and not any(p is q for q in conflicts)]

    def _deferred(self, placement: Placement, start: int) -> Placement | None:
        """``placement`` approaching from ``start`` over at least :data:`BLEND_LATENTS`, its stroke moved later as
        that needs (None when more than :data:`MAX_DEFER_S`)."""
        stroke = max(placement.stroke, start + BLEND_LATENTS)
        if stroke - placement.stroke > self.max_defer:
            return None
        shift = stroke - placement.stroke
        first = placement.first + shift
        start = max(start, first)  # a moved clip may start after the hand-over: it approaches from its own start
        return replace(placement, first=first, start=start, stop=placement.stop + shift,
                       ramp_in=max(1, min(BLEND_LATENTS, stroke - start)),
                       late_s=max(0.0, self._time(stroke) - placement.cue.time))

    def _returns(self, conflicts: list[Placement], start: int, next_latent: int) -> list[Placement] | None:
        """Each of ``conflicts`` with its whole return moved earlier, to end (arms down) where a gesture approaching
        from ``start`` begins: its hold cut short instead, cross-fading into the return over :data:`BLEND_LATENTS`.
        None when one cannot: its return is not known or already cut, or it would begin within :data:`HOLD_LATENTS`
        of its stroke or before ``next_latent``."""
        returns = []
        for placement in conflicts:
            clip = placement.clip
            skip = placement.first + clip.num_latents - 1 - start  # the clip's last latent on ``start``
            begin = placement.first + clip.release_latent - skip - BLEND_LATENTS + 1  # the cross-fade into the return
            earliest = max(placement.stroke + HOLD_LATENTS, next_latent)
            if clip.release_latent < 0 or not placement.whole or begin < earliest:
                return None
            returns.append(replace(placement, skip=skip, start=begin, stop=start, ramp_in=BLEND_LATENTS,
                                   ramp_out=min(placement.ramp_out, BLEND_LATENTS)))
        return returns

    def _share(self, placement: Placement, conflicts: list[Placement], earlier: Placement, busy: np.ndarray
               ) -> CueOutcome:
        """The later gesture's own parts (a bow's torso) play on time alongside the earlier ones; the parts they share
        (the arms; ``busy``: (C,) the channels the earlier ones impose) hand over once the latest has held its stroke
        :data:`HOLD_LATENTS`, cross-fading over :data:`BLEND_LATENTS` (the earlier returns cut short), or never when
        the later has ended by then."""
        columns = np.logical_or.reduce([p.clip.columns for p in conflicts])
        own = replace(placement, clip=part_clip(placement.clip, ~busy, ~columns))
        hand_over = max(placement.start, earlier.stroke + HOLD_LATENTS)
        parts = [own]
        if hand_over + 2 * BLEND_LATENTS <= placement.stop:
            parts.append(replace(placement, clip=part_clip(placement.clip, busy, columns), start=hand_over,
                                 ramp_in=BLEND_LATENTS))
        if not self._hand_over(conflicts if len(parts) > 1 else [], hand_over, parts):
            return self._drop(placement.cue, "the gestures around it leave no room")
        for part in parts[1:]:
            self._insert(part)
        note = f"with the {_names(conflicts)}" + (", the shared parts after its stroke" if len(parts) > 1 else "")
        return self._accept(own, "blended", note)

    def _hand_over(self, conflicts: list[Placement], start: int, parts: list[Placement],
                   returns: list[Placement] | None = None) -> bool:
        """Cut each of ``conflicts`` to cross-fade over :data:`BLEND_LATENTS` from ``start`` (one that would only
        start after that is taken out), or from the start of its moved return where ``returns`` has one for each, to
        make room for ``parts``; False, changing nothing, when a part meets a gesture that is not one of them."""
        if any(not any(p is q for q in conflicts) for part in parts for p in self._overlapping(part)):
            return False
        for k, placement in enumerate(conflicts):
            cut_from = start if returns is None else returns[k].start
            cut = replace(placement, stop=min(placement.stop, cut_from + BLEND_LATENTS - 1),
                          ramp_out=min(placement.ramp_out, BLEND_LATENTS))
            self._replace(placement, cut if cut.start <= cut.stop else None)
        for moved in returns or ():
            self._insert(moved)
        return True

    def _starting_within(self, low: int, high: int) -> list[Placement]:
        """The placements whose first latent is within [low, high] (binary search on the ordered list)."""
        start = bisect.bisect_left(self.placements, low, key=_first_latent)
        return self.placements[start : bisect.bisect_right(self.placements, high, key=_first_latent)]

    def _covering(self, latent: int) -> list[Placement]:
        """The placements playing on ``latent``, in the order of their cues' times ("wave+bow")."""
        covering = [p for p in self._starting_within(latent - self.longest + 1, latent) if p.covers(latent)]
        return sorted(covering, key=lambda p: p.cue.time)

    def _overlapping(self, placement: Placement) -> list[Placement]:
        nearby = self._starting_within(placement.start - self.longest + 1, placement.stop)  # all that can overlap
        return [p for p in nearby if p.overlaps(placement)]

    def _insert(self, placement: Placement) -> None:
        bisect.insort(self.placements, placement, key=_first_latent)

    def _replace(self, old: Placement, new: Placement | None) -> None:
        """Put ``new`` (the same first latent) where ``old`` is, or take ``old`` out (None)."""
        low = bisect.bisect_left(self.placements, old.first, key=_first_latent)
        index = next(i for i in range(low, len(self.placements)) if self.placements[i] is old)
        if new is None:
            del self.placements[index]
        else:
            self.placements[index] = new

    def _accept(self, placement: Placement, status: str, note: str) -> CueOutcome:
        self._insert(placement)
        return self._record(CueOutcome(placement.cue, status, self._time(placement.stroke), note))

    def _drop(self, cue: Cue, note: str) -> CueOutcome:
        return self._record(CueOutcome(cue, "dropped", None, note))

    def _record(self, outcome: CueOutcome) -> CueOutcome:
        self.counts[outcome.status] += 1
        self.outcomes.append(outcome)
        if outcome.status == "dropped":
            self._drop_log.log(logging.WARNING, outcome.describe())
        elif outcome.status != "on time" or outcome.cue.source == CONTROL_SOURCE:
            self._note_log.log(logging.INFO, outcome.describe())
        return outcome

    def imposition(self, latent: int) -> Imposition | None:
        """What the clips covering stream latent ``latent`` impose on it (None when none does)."""
        covering = self._covering(latent)
        return Imposition.of(covering, latent) if covering else None

    def forget_before(self, latent: int) -> None:
        """Drop placements that ended before ``latent``: those starting a whole longest clip before it, and the
        ended ones among the few starting after that."""
        del self.placements[: bisect.bisect_left(self.placements, latent - self.longest + 1, key=_first_latent)]
        started = bisect.bisect_left(self.placements, latent, key=_first_latent)  # the few that may have ended
        self.placements[:started] = [p for p in self.placements[:started] if p.stop >= latent]

    def summary(self) -> dict[str, int]:
        """Cues by outcome over the whole stream (every status, zeros included)."""
        return {status: self.counts[status] for status in STATUSES}


def _first_latent(placement: Placement) -> int:
    return placement.first


def _names(placements: list[Placement]) -> str:
    """The gestures of ``placements`` in their cues' order, once each ("wave and call")."""
    return " and ".join(dict.fromkeys(p.cue.gesture for p in sorted(placements, key=lambda p: p.cue.time)))
