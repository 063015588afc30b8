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
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError

DEFAULT_REFRACTORY_S = 4.0  # the same gesture again within this many seconds is dropped
RAMP_LATENTS = 4  # latents over which the imposition weight rises to 1 (and falls back) at each end of a clip


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
                 refractory_s: float = DEFAULT_REFRACTORY_S) -> None:
        self.clips = dict(clips)
        self.seconds_per_latent = seconds_per_latent
        self.refractory_s = refractory_s
        self.placements: list[Placement] = []
        self.dropped = 0  # cues refused: refractory time or a body part already busy
        self._last_stroke: dict[str, float] = {}  # gesture -> stream time of its last placed stroke

    def check(self, gesture: str) -> GestureClip:
        """The clip of ``gesture``; a one-line UserError naming the known ones otherwise."""
        if gesture not in self.clips:
            raise UserError(f"unknown gesture {gesture!r}; known: {', '.join(sorted(self.clips))}")
        return self.clips[gesture]

    def place(self, cue: Cue, next_latent: int) -> Placement | None:
        """Place ``cue`` no earlier than ``next_latent`` (the first latent not generated yet); None when it is
        dropped (refractory time, or a part it moves is busy)."""
        clip = self.check(cue.gesture)
        wanted = math.floor(cue.time / self.seconds_per_latent) - clip.stroke_latent
        first = max(wanted, next_latent)
        stroke_time = (first + clip.stroke_latent) * self.seconds_per_latent
        placement = Placement(cue, clip, first, max(0.0, stroke_time - cue.time))
        if self._refused(placement, stroke_time):
            self.dropped += 1
            return None
        self.placements.append(placement)
        self._last_stroke[cue.gesture] = stroke_time
        return placement

    def _refused(self, placement: Placement, stroke_time: float) -> bool:
        previous = self._last_stroke.get(placement.cue.gesture)
        if previous is not None and abs(stroke_time - previous) < self.refractory_s:
            return True
        return any(other.first <= placement.last and placement.first <= other.last
                   and bool((other.clip.channels & placement.clip.channels).any()) for other in self.placements)

    def imposition(self, latent: int) -> Imposition | None:
        """What the clips covering stream latent ``latent`` impose on it (None when none does)."""
        covering = [p for p in self.placements if p.covers(latent)]
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
        """Drop placements that ended before ``latent`` (their strokes still count for the refractory time)."""
        self.placements = [p for p in self.placements if p.last >= latent]
