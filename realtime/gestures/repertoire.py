"""The gestures a model's streams can perform: the lexicon read, each gesture's takes chosen for the style and
encoded into the model's latent space once per session factory (:func:`load_repertoire`), with what cues them.

A built lexicon's gestures are cued by the speech acts of words (:mod:`gesturecast.realtime.gestures.speech_acts`);
a user's folder's trigger phrases cue their gestures wherever they are said.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.gestures.clips import ClipMotion, encode_clips, mirrorable, performances
from gesturecast.realtime.gestures.cues import GestureClip
from gesturecast.realtime.gestures.lexicon import (
    DEFAULT_STYLE,
    LEXICON_FILE,
    GestureEntry,
    GestureVariant,
    Lexicon,
    load_lexicon,
)
from gesturecast.settings import Settings

MEANT_STYLES = {"raise-both": "active", "guide": "proud"}  # gesture -> the take that means it, where the neutral
# one falls short: Bandai's neutral raise stops at the top of the head (all 74 neutral takes: wrists 5-19 cm above
# the head joint), a cheer is the arms overhead (its active take: 34 cm); the neutral guide holds a bent arm below
# the shoulder, presenting holds an open arm out at shoulder height (its proud take)


@dataclass(frozen=True)
class GestureRepertoire:
    """clips: the lexicon in a model's latent space, each gesture's performances in turn; triggers: (gesture, phrases
    that always cue it); speech_acts: whether the speech acts of words cue the gestures. The default has none."""

    clips: tuple[GestureClip, ...] = ()
    triggers: tuple[tuple[str, tuple[str, ...]], ...] = ()
    speech_acts: bool = False

    @property
    def names(self) -> tuple[str, ...]:
        """Each gesture once, in the lexicon's order."""
        return tuple(self.performances())

    def performances(self) -> dict[str, list[GestureClip]]:
        """Each gesture's performances, in the order a stream plays them."""
        by_name: dict[str, list[GestureClip]] = {}
        for clip in self.clips:
            by_name.setdefault(clip.name, []).append(clip)
        return by_name

    def first_performances(self) -> dict[str, GestureClip]:
        return {name: clips[0] for name, clips in self.performances().items()}


def load_repertoire(settings: Settings, bundle: ModelBundle) -> GestureRepertoire:
    """The repertoire of ``settings.gestures`` (none when it is None) in ``bundle``'s latent space: each gesture's
    takes in the style variant named like the settings' style label (:func:`performed_variant`), as performances
    drawn from the seed."""
    if settings.gestures is None:
        return GestureRepertoire()
    lexicon = load_lexicon(settings.gestures)
    prompt = settings.style_prompt()
    style = prompt.value if prompt.kind == "label" else None
    built = (Path(settings.gestures) / LEXICON_FILE).is_file()  # the Bandai lexicon: cued by speech acts
    motions = performed_motions(lexicon, style, settings.seed, mirror=built)
    triggers = () if built else tuple((entry.name, entry.triggers) for entry in lexicon)
    return GestureRepertoire(encode_clips(bundle, motions, settings.threads), triggers, built)


def performed_motions(lexicon: Lexicon, style: str | None, seed: int, mirror: bool = False) -> list[ClipMotion]:
    """Every gesture's performances for a stream in ``style`` at ``seed``: the recorded takes of its performed
    variant (:func:`performed_variant`) in turn, each at a tempo and amplitude drawn from the seed; with
    ``mirror`` (the built lexicon, not a user's clips), every other one of a gesture that names no hand with the
    other hand."""
    motions: list[ClipMotion] = []
    for entry in lexicon:
        takes = [ClipMotion(entry.name, np.asarray(take.features, np.float32), take.stroke_frame, entry.parts,
                            take.source) for take in entry.takes(performed_variant(entry, style).style)]
        motions += performances(takes, seed, mirror=mirror and mirrorable(entry.name))
    return motions


def performed_variant(entry: GestureEntry, style: str | None) -> GestureVariant:
    """The clip of ``entry`` a stream in ``style`` plays: the style's own, else the one of
    :data:`MEANT_STYLES` where the neutral take falls short of what the gesture means, else the neutral one."""
    variant = entry.variant(style)
    meant = MEANT_STYLES.get(entry.name)
    return entry.variant(meant) if variant.style == DEFAULT_STYLE and meant in entry.styles else variant
