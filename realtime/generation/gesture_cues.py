"""Gesture cues carried out by the generator: a lexicon clip's body-part latents imposed while denoising its window.

A :class:`Cue` asks for a gesture's stroke at a stream time (a word's start, a button press). :class:`CuePlan`
places it on the latent grid so that the clip's stroke latent covers that time (or, for a cue that arrives too
late, the first latent not yet generated, reported late by how much). While a placed clip covers latent ``i``,
:meth:`CuePlan.imposition` gives the clip's latent ``k = i − first`` and a weight per latent channel: the channels
of the parts the gesture moves (arms for a wave, torso and arms for a bow), ramped up over the clip's first
:data:`RAMP_LATENTS` latents and down over its last ones. The generator pulls its x̂0 prediction toward that latent
at every sampler step (inpainting those channels, as motion-diffusion models inpaint joints), so the approach and
the return blend with what it generates from the context, and the parts not gesturing keep following the speech.
The decoded poses of those parts are then blended toward the clip's own joint rotations with the same ramp (per
frame): the VQ decoder alone flattens some gestures (a bye's raised hand came out 0.2 m lower than recorded), and
the blend keeps their shape while the latents keep the neighbouring motion consistent with it.

A gesture is not repeated within :data:`DEFAULT_REFRACTORY_S`, and a body part does one gesture at a time: a cue
that would overlap a placed clip on a shared part is dropped (and counted). The plan is deterministic in stream
time, so streaming and offline runs with the same cues give the same poses.

The placements are kept in order of their first latent, so placing a cue and imposing a latent look only at the
clips that can overlap it (a clip is at most the lexicon's longest): their cost does not grow with the number of
cues waiting. A plan holds at most :data:`MAX_PLACEMENTS` of them (:class:`CueRefused` beyond), and
:meth:`CuePlan.check_ahead` refuses cue times more than :data:`MAX_AHEAD_S` ahead of the stream (live doors).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError

DEFAULT_REFRACTORY_S = 4.0  # the same gesture again within this many seconds is dropped
RAMP_LATENTS = 4  # latents over which the imposition weight rises to 1 (and falls back) at each end of a clip
MAX_PLACEMENTS = 20_000  # placed cues still to come (a transcript's hours of gestures); beyond: CueRefused
MAX_AHEAD_S = 300.0  # words sent live (a TTS reply) are at most this far ahead of the stream
MAX_CUE_TIME_S = 1e6  # a cue time beyond this (or not finite) is not a stream time (11 days)


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
    """

    name: str
    latents: np.ndarray
    channels: np.ndarray
    stroke_latent: int
    features: np.ndarray
    columns: np.ndarray

    @property
    def num_latents(self) -> int:
        return self.latents.shape[0]


@dataclass(frozen=True)
class Placement:
    """A cue placed on the latent grid: clip latent ``k`` is imposed on stream latent ``first + k``."""

    cue: Cue
    clip: GestureClip
    first: int
    late_s: float  # how much later than asked the stroke lands (0 when the cue came early enough)

    @property
    def last(self) -> int:
        return self.first + self.clip.num_latents - 1

    def covers(self, latent: int) -> bool:
        return self.first <= latent <= self.last


def ramp_weight(k: int, length: int, ramp: int = RAMP_LATENTS) -> float:
    """Imposition weight of clip latent ``k`` of ``length``: rises over the first ``ramp``, falls over the last."""
    return min(1.0, (k + 1) / (ramp + 1), (length - k) / (ramp + 1))


@dataclass(frozen=True)
class Imposition:
    """What the placed clips ask of one latent: its latent (C,) target and weights, the decoded poses' (d, D)
    target features and per-frame weights, and the gesture names ("wave", "bow+guide")."""

    target: np.ndarray
    weights: np.ndarray
    pose: np.ndarray
    pose_weights: np.ndarray
    names: str

    def add(self, placement: Placement, k: int, d: int) -> None:
        """Clip latent ``k`` of ``placement`` on its channels and columns (ramped per latent and per frame)."""
        clip = placement.clip
        self.target[clip.channels] = clip.latents[k, clip.channels]
        self.weights[clip.channels] = ramp_weight(k, clip.num_latents)
        frames = np.arange(k * d, (k + 1) * d)  # (d,) clip frames of this latent
        ramp = np.array([ramp_weight(f, clip.features.shape[0], RAMP_LATENTS * d) for f in frames], np.float32)
        self.pose[:, clip.columns] = clip.features[frames][:, clip.columns]
        self.pose_weights[:, clip.columns] = ramp[:, None]

    def blend(self, features: np.ndarray) -> np.ndarray:
        """(d, D) decoded features pulled toward the clip's joint rotations."""
        return features + self.pose_weights * (self.pose - features)


class CuePlan:
    """Placed cues of one stream (see the module docstring); ``seconds_per_latent`` = d / fps."""

    def __init__(self, clips: Mapping[str, GestureClip], seconds_per_latent: float,
                 refractory_s: float = DEFAULT_REFRACTORY_S, max_placements: int = MAX_PLACEMENTS) -> None:
        self.clips = dict(clips)
        self.seconds_per_latent = seconds_per_latent
        self.refractory_s = refractory_s
        self.max_placements = max_placements
        self.longest = max((clip.num_latents for clip in self.clips.values()), default=1)  # latents of a clip
        self.placements: list[Placement] = []  # in order of their first latent
        self.dropped = 0  # cues refused: refractory time or a body part already busy
        self._last_stroke: dict[str, float] = {}  # gesture -> stream time of its last placed stroke

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

    def place(self, cue: Cue, next_latent: int) -> Placement | None:
        """Place ``cue`` no earlier than ``next_latent`` (the first latent not generated yet); None when it is
        dropped (refractory time, or a part it moves is busy); CueRefused when the plan is full."""
        clip = self.check(cue.gesture)
        if not math.isfinite(cue.time) or cue.time > MAX_CUE_TIME_S:
            raise CueRefused(f"gesture {cue.gesture} at {cue.time!r} s: not a stream time (at most {MAX_CUE_TIME_S:g})")
        self._check_room()
        wanted = math.floor(cue.time / self.seconds_per_latent) - clip.stroke_latent
        first = max(wanted, next_latent)
        stroke_time = (first + clip.stroke_latent) * self.seconds_per_latent
        placement = Placement(cue, clip, first, max(0.0, stroke_time - cue.time))
        if self._refused(placement, stroke_time):
            self.dropped += 1
            return None
        bisect.insort(self.placements, placement, key=_first_latent)
        self._last_stroke[cue.gesture] = stroke_time
        return placement

    def _starting_within(self, low: int, high: int) -> list[Placement]:
        """The placements whose first latent is within [low, high] (binary search on the ordered list)."""
        start = bisect.bisect_left(self.placements, low, key=_first_latent)
        return self.placements[start : bisect.bisect_right(self.placements, high, key=_first_latent)]

    def _refused(self, placement: Placement, stroke_time: float) -> bool:
        previous = self._last_stroke.get(placement.cue.gesture)
        if previous is not None and abs(stroke_time - previous) < self.refractory_s:
            return True
        nearby = self._starting_within(placement.first - self.longest + 1, placement.last)  # all that can overlap
        return any(other.first <= placement.last and placement.first <= other.last
                   and bool((other.clip.channels & placement.clip.channels).any()) for other in nearby)

    def imposition(self, latent: int) -> Imposition | None:
        """What the clips covering stream latent ``latent`` impose on it (None when none does)."""
        covering = [p for p in self._starting_within(latent - self.longest + 1, latent) if p.covers(latent)]
        if not covering:
            return None
        first = covering[0].clip
        d = first.features.shape[0] // first.num_latents
        imposition = Imposition(np.zeros(first.latents.shape[1], np.float32), np.zeros(first.latents.shape[1],
                                np.float32), np.zeros((d, first.features.shape[1]), np.float32),
                                np.zeros((d, first.features.shape[1]), np.float32),
                                "+".join(p.cue.gesture for p in covering))
        for placement in covering:
            imposition.add(placement, latent - placement.first, d)
        return imposition

    def forget_before(self, latent: int) -> None:
        """Drop placements that ended before ``latent`` (their strokes still count for the refractory time): those
        starting a whole longest clip before it, and the ended ones among the few starting after that."""
        del self.placements[: bisect.bisect_left(self.placements, latent - self.longest + 1, key=_first_latent)]
        started = bisect.bisect_left(self.placements, latent, key=_first_latent)  # the few that may have ended
        self.placements[:started] = [p for p in self.placements[:started] if p.last >= latent]


def _first_latent(placement: Placement) -> int:
    return placement.first
