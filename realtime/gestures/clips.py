"""Lexicon clips in one model's latent space: canonical motion features → the model's VQ encoder → normalised
latents, with the channels of the body parts the gesture moves (:class:`GestureClip`).

The whole clip is encoded (the encoder sees its approach and return); only the moving parts' channels are imposed,
so the clip's legs, root and facing never reach the stream.

**Performances.** A gesture is not played as one canned clip: :func:`performances` makes :data:`PERFORMANCES`
versions of it (or the next multiple of its number of takes), each a recorded take of the style (the lexicon keeps
up to three per style where the data has several; the takes in turn, in an order drawn from the seed) at its own
tempo (:data:`TEMPO_RANGE`, resampled in time) and amplitude (:data:`AMPLITUDE_RANGE`, the moving joints' 6D
rotation features scaled about the clip's first pose), drawn from the stream's seed: the amplitude from the lower
or the upper third of its range, in turns of two where the hands alternate (two shallow bows, then two deep ones)
and every time otherwise, a larger one slower (the tempo from the lower half of its range), a smaller one quicker.
A gesture of the built lexicon whose name says no hand (a bye, a guide, a bow; not wave-right) is played with the
other hand every other time (:func:`mirrored`: the left and right joints swapped and reflected), unless it is
symmetric (both hands wave or rise: its mirror within :data:`SYMMETRIC_WITHIN_M` of it, :func:`symmetric`); then
the other hand is no other performance, so the hands lead in turns (the other arm turns :data:`LAGGING_ARM` as
far). The cue plan plays them in turn (and again from the first), so two plays of a gesture in a row are different
takes where there are two or more, at another size or with the other hand, at other tempos, and another seed plays
others. Each clip also knows where its hold ends (:func:`gesturecast.realtime.gestures.strokes.release_frame`), so
the cue plan can cut a hold short and keep the return.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.body_parts import PART_JOINTS, joint_columns
from gesturecast.models.motion.motion_features import features_to_motion, mirror_motion, motion_to_features
from gesturecast.models.runtime.bundle import ModelBundle, VQEncoderRuntime
from gesturecast.realtime.gestures.cues import GestureClip
from gesturecast.realtime.gestures.reattach import body_frame_roots
from gesturecast.realtime.gestures.strokes import body_frame_positions, release_frame

PERFORMANCES = 4  # versions of each gesture per stream, played in turn
TEMPO_RANGE = (0.85, 1.15)  # a performance's speed, relative to the recorded clip
AMPLITUDE_RANGE = (0.9, 1.2)  # how far its moving joints turn, relative to the recorded clip
SIDES = ("-left", "-right")  # a gesture named with one of these is performed with that hand only
SYMMETRIC_WITHIN_M = 0.04  # mean joint distance of a take from its mirror below which it reads the same mirrored
LAGGING_ARM = 0.85  # how far the arm that does not lead a symmetric gesture turns, relative to the leading one
ARM_SIDES = ("Left", "Right")  # joint-name prefixes of the two arms
_SYMMETRIC_TAKES: dict[bytes, bool] = {}  # a take's features' digest -> whether it is symmetric (:func:`symmetric`)


@dataclass(frozen=True)
class ClipMotion:
    """A lexicon clip as motion: (T, D) canonical motion features at the model's fps, its stroke frame, the
    body parts it moves (names of the model's ``body_parts``) and the recorded take it comes from."""

    name: str
    features: np.ndarray
    stroke_frame: int
    parts: tuple[str, ...]
    source: str = ""


def part_mask(bundle: ModelBundle, parts: Iterable[str], name: str) -> np.ndarray:
    """(C,) bool: the latent channels of ``parts``; UserError for a part the model does not have."""
    mask = np.zeros(bundle.denoiser_config.latent_dim, bool)
    for part in parts:
        if part not in bundle.part_channels:
            raise UserError(f"gesture {name!r} moves the body part {part!r}, which this model does not have "
                            f"(it has {', '.join(bundle.part_channels)})")
        mask[bundle.part_channels[part]] = True
    return mask


def encode_clip(bundle: ModelBundle, motion: ClipMotion, encoder: VQEncoderRuntime) -> GestureClip:
    """The clip's normalised latents (N, C) and part channels for ``bundle``'s model (``encoder``: its VQ encoder)."""
    d = bundle.frames_per_latent
    usable = motion.features.shape[0] - motion.features.shape[0] % d
    if usable == 0 or not 0 <= motion.stroke_frame < usable:
        raise UserError(f"gesture {motion.name!r}: {motion.features.shape[0]} frames with the stroke at frame "
                        f"{motion.stroke_frame}; it needs at least {d} frames and its stroke inside them")
    features = np.asarray(motion.features[:usable], np.float32)  # (T', D)
    latents = encoder.encode(bundle.motion_stats.normalize(features))  # (N, C)
    columns = rotation_columns(motion.parts, features.shape[1])
    release = release_frame(body_frame_positions(features_to_motion(features)))
    return GestureClip(motion.name, bundle.latent_stats.normalize(latents).astype(np.float32),
                       part_mask(bundle, motion.parts, motion.name), motion.stroke_frame // d, features, columns,
                       tuple(body_frame_roots(features, columns)), max(release, motion.stroke_frame) // d)


def rotation_columns(parts: Iterable[str], feature_dim: int) -> np.ndarray:
    """(D,) bool: the joint-rotation feature columns of ``parts`` (the root's height and travel excluded)."""
    columns = np.zeros(feature_dim, bool)
    for part in parts:
        columns[[c for joint in PART_JOINTS[part] for c in joint_columns(joint)]] = True
    return columns


def side_columns(parts: Iterable[str], side: str, feature_dim: int) -> np.ndarray:
    """(D,) bool: the rotation columns of the joints of ``parts`` on one ``side`` ("Left" or "Right")."""
    columns = np.zeros(feature_dim, bool)
    for part in parts:
        columns[[c for joint in PART_JOINTS[part] if joint.startswith(side) for c in joint_columns(joint)]] = True
    return columns


def encode_clips(bundle: ModelBundle, motions: Iterable[ClipMotion], threads: int = 1) -> tuple[GestureClip, ...]:
    """Every clip through one encoder session (a session per clip cost 0.2 s of every session build)."""
    encoder = bundle.vq_encoder(threads)
    return tuple(encode_clip(bundle, motion, encoder) for motion in motions)


def performance(motion: ClipMotion, tempo: float, amplitude: float, lagging: str | None = None) -> ClipMotion:
    """``motion`` played ``tempo`` times as fast (linear resampling in time) with its moving joints' rotations
    scaled by ``amplitude`` about its first pose (6D features, re-orthonormalised when decoded); the joints of the
    ``lagging`` side ("Left" or "Right"), if any, by :data:`LAGGING_ARM` times as much."""
    frames = motion.features.shape[0]
    count = max(2, round(frames / tempo))
    source = np.linspace(0.0, frames - 1, count)  # (T',) fractional source frames
    low = np.floor(source).astype(int)
    high = np.minimum(low + 1, frames - 1)
    weight = (source - low)[:, None]  # (T', 1)
    features = (1 - weight) * motion.features[low] + weight * motion.features[high]  # (T', D)
    scale = np.where(rotation_columns(motion.parts, features.shape[1]), amplitude, 1.0)  # (D,)
    if lagging:
        scale[side_columns(motion.parts, lagging, features.shape[1])] *= LAGGING_ARM
    features = features[0] + scale * (features - features[0])  # (T', D)
    stroke = min(count - 1, round(motion.stroke_frame / tempo))
    return replace(motion, features=features.astype(np.float32), stroke_frame=stroke)


def mirrored(motion: ClipMotion) -> ClipMotion:
    """``motion`` performed with the other hand: its left and right joints swapped and reflected (the skeleton's
    mirror, an exact involution), the stroke where it was."""
    return replace(motion, features=motion_to_features(mirror_motion(features_to_motion(motion.features))))


def symmetric(motion: ClipMotion) -> bool:
    """Whether ``motion`` reads the same with the other hand: its mirror's joints are on average within
    :data:`SYMMETRIC_WITHIN_M` of its own (the shipped both-hands waves and raises 1.6–2.6 cm, a bow 6 cm, one-hand
    gestures 7–16 cm). A property of the recorded take, worked out once per process (two forward kinematics of the
    whole take: 60 of a session build's 90 ms otherwise)."""
    key = hashlib.blake2b(np.ascontiguousarray(motion.features).tobytes(), digest_size=16).digest()
    if key not in _SYMMETRIC_TAKES:
        positions = features_to_motion(motion.features).positions()  # (T, J, 3)
        other = features_to_motion(mirrored(motion).features).positions()  # (T, J, 3)
        _SYMMETRIC_TAKES[key] = float(np.linalg.norm(positions - other, axis=-1).mean()) < SYMMETRIC_WITHIN_M
    return _SYMMETRIC_TAKES[key]


def mirrorable(name: str) -> bool:
    """Whether a gesture reads the same with the other hand: any whose name does not say which (wave-right)."""
    return not name.endswith(SIDES)


def played_larger(k: int, hands_alternate: bool) -> int:
    """Whether the ``k``-th performance comes from the upper third of the amplitude range (1) or the lower (0), before
    the seed's flip: in turns of two where the hands alternate (every hand-size pair over four), else every time."""
    return ((k + 1) // 2 if hands_alternate else k) % 2


def performances(takes: Sequence[ClipMotion], seed: int, count: int = PERFORMANCES, mirror: bool = False
                 ) -> list[ClipMotion]:
    """At least ``count`` performances of one gesture from its recorded ``takes`` (one or more, the same name), as
    many as the next multiple of the number of takes: the takes in turn, in an order drawn from ``seed`` and the
    gesture's name, each at its own tempo and amplitude drawn from them too (the same seed gives the same
    performances). With ``mirror`` (and takes that are not :func:`symmetric`), every other performance is played
    with the other hand, each take with both hands over the performances, and the amplitude comes from the lower and
    the upper third of its range in turns of two; otherwise the amplitude changes third every time, and with
    ``mirror`` and symmetric takes the hands lead in turns. A larger performance is slower. Played in turn
    and again from the first, consecutive ones are different takes when there are two or more, and differ in size
    or hand (both in turn)."""
    if not takes:
        raise ValueError("a gesture's performances need at least one take")
    rng = np.random.default_rng([seed, *takes[0].name.encode()])
    order = rng.permutation(len(takes))
    total = -(-count // len(takes)) * len(takes)
    hand, size = (int(k) for k in rng.integers(2, size=2))
    even = mirror and all(symmetric(take) for take in takes)  # both hands alike: they lead in turns instead
    other_hands = mirror and not even
    low, high = AMPLITUDE_RANGE
    third = (high - low) / 3
    motions = []
    for k in range(total):
        larger = played_larger(k, other_hands) ^ size
        amplitude = rng.uniform(high - third, high) if larger else rng.uniform(low, low + third)
        tempo = rng.uniform(TEMPO_RANGE[0], 1.0) if larger else rng.uniform(1.0, TEMPO_RANGE[1])  # larger is slower
        lagging = ARM_SIDES[(k + hand) % 2] if even else None
        motion = performance(takes[order[k % len(takes)]], float(tempo), float(amplitude), lagging)
        other_hand = (k + (k // len(takes) if len(takes) % 2 == 0 else 0) + hand) % 2  # a take's next round flips
        motions.append(mirrored(motion) if other_hands and other_hand else motion)
    return motions
