"""A seed gesture from a motion file: the stream starts from its pose instead of the idle pose.

DiffuseStyleGesture starts each clip from *seed gesture* frames, the end of the motion before it. Here
``--seed-motion FILE`` reads any file :func:`load_motion_file` reads (a BVH of any supported skeleton,
retargeted like a ``motion:`` style prompt, or SMPL-X ``.npz``) and keeps its **last** frames: the
stream continues from where that motion ends, as a next clip continues the previous one.

- The last ``W·d`` frames (``W`` latents of denoiser history, ``d`` frames per latent: the most the history
  holds) are encoded into the generator's history (:meth:`Generator.reset` ``seed_pose``), so the first
  generated latents attend to the seed.
- The very last frame, facing +Z, is the first pose shown; the session cross-fades from it into the
  stream (speech gestures, or idle in silence) over the idle fade time (:class:`GestureSession`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.motion_features import ROOT_HEIGHT, features_to_rotations, motion_to_features
from gesturecast.models.motion.retarget import load_motion_file
from gesturecast.models.runtime.bundle import ModelBundle

FACING_FORWARD = 0.0  # yaw of the start pose: the anchor's direction (+Z)


@dataclass(frozen=True, eq=False)
class SeedMotion:
    """The seed of a stream: history frames for the generator and the pose it starts from."""

    features: np.ndarray  # (T, D) denormalised motion features, T a multiple of d, T <= W·d
    rotations: np.ndarray  # (J, 4) XYZW local rotations of the last frame, facing +Z
    height: float  # hips height of the last frame, metres


def load_seed_motion(path: Path, bundle: ModelBundle) -> SeedMotion:
    """The seed gesture of ``path`` for ``bundle``'s model; one-line UserError for a missing, unreadable or
    too short file (the loader's own errors name unsupported skeletons and missing joints)."""
    if not path.is_file():
        raise UserError(f"seed motion not found: {path}")
    features = motion_to_features(load_motion_file(path))  # (T, D)
    d = bundle.frames_per_latent
    if len(features) < d:
        raise UserError(f"seed motion {path} has {len(features)} frames; it needs at least {d} (one latent)")
    usable = min(len(features) - len(features) % d, bundle.denoiser_config.window * d)
    last = features[-1]  # (D,)
    return SeedMotion(features[-usable:], features_to_rotations(last, np.asarray(FACING_FORWARD)),
                      float(last[ROOT_HEIGHT][0]))
