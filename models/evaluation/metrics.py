"""Objective gesture metrics on joint positions (T, J, 3) in metres at `fps` frames per second.

Formulas and sources are listed in docs/metrics.md. This module holds the kinematic metrics and
collects the others: beat consistency (:mod:`.beat_consistency`) and the Fréchet distance used
for FGD (:mod:`.frechet`).

- acceleration / jerk (GENEA Challenge 2020 numerical evaluation, Kucherenko et al. 2021): the
  mean magnitude of the 2nd / 3rd finite difference of joint positions times fps² / fps³,
  over frames and joints (m/s², m/s³);
- liveliness: generated vs real mean joint speed, and the ratio of joint-speed variances;
- diversity: EMAGE's L1Div within a clip, and the mean pairwise distance between clips
  generated for the same audio with different seeds.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from gesturecast.models.evaluation.beat_consistency import (
    BeatConsistencyConfig,
    beat_alignment,
    beat_consistency,
    joint_speeds,
    speech_onsets,
)
from gesturecast.models.evaluation.frechet import (
    frechet_distance,
    frechet_distance_from_statistics,
    gaussian_statistics,
)

__all__ = [
    "BeatConsistencyConfig", "Liveliness", "acceleration", "beat_alignment", "beat_consistency",
    "frechet_distance", "frechet_distance_from_statistics", "gaussian_statistics", "jerk", "joint_speeds",
    "l1_diversity", "liveliness", "liveliness_from_speeds", "root_relative", "seed_diversity", "speech_onsets",
]  # fmt: skip


def _finite_difference_magnitude(positions: np.ndarray, fps: float, order: int) -> float:
    """Mean over frames and joints of ‖Δⁿ p‖ · fpsⁿ (forward differences of order n)."""
    if positions.shape[0] <= order:
        raise ValueError(f"need more than {order} frames, got {positions.shape[0]}")
    difference = np.diff(positions, n=order, axis=0) * fps**order  # (T - n, J, 3)
    return float(np.linalg.norm(difference, axis=-1).mean())


def acceleration(positions: np.ndarray, fps: float) -> float:
    """Mean acceleration magnitude (m/s²): ‖p[t+2] − 2p[t+1] + p[t]‖ · fps², averaged."""
    return _finite_difference_magnitude(positions, fps, 2)


def jerk(positions: np.ndarray, fps: float) -> float:
    """Mean jerk magnitude (m/s³): ‖p[t+3] − 3p[t+2] + 3p[t+1] − p[t]‖ · fps³, averaged."""
    return _finite_difference_magnitude(positions, fps, 3)


@dataclass(frozen=True)
class Liveliness:
    """speed_ratio: mean joint speed, generated / real (1 = as lively as the data; a frozen pose 0).
    variance_ratio: variance of joint speed, generated / real (jitter or bursts push it above 1)."""

    speed_ratio: float
    variance_ratio: float


def liveliness(generated: np.ndarray, real: np.ndarray, fps: float) -> Liveliness:
    """Compare the joint speeds of generated and real positions (each (T, J, 3), same joints)."""
    return liveliness_from_speeds(joint_speeds(generated, fps), joint_speeds(real, fps))


def liveliness_from_speeds(gen_speed: np.ndarray, real_speed: np.ndarray) -> Liveliness:
    """:func:`liveliness` from joint speeds of any shape (e.g. several clips' (T, J) speeds concatenated)."""
    if real_speed.mean() == 0.0 or real_speed.var() == 0.0:
        raise ValueError("the real motion does not move: liveliness is undefined")
    return Liveliness(float(gen_speed.mean() / real_speed.mean()), float(gen_speed.var() / real_speed.var()))


def root_relative(positions: np.ndarray) -> np.ndarray:
    """Positions (T, J, 3) with the root joint (index 0) moved to the origin in every frame."""
    return positions - positions[:, :1]


def l1_diversity(positions: np.ndarray) -> float:
    """EMAGE's L1Div: (1/T) Σ_t Σ_{j,d} |p_tjd − p̄_jd| on root-relative positions (metres, summed
    over the J·3 coordinates, so comparable only between clips on the same skeleton)."""
    relative = root_relative(positions).reshape(positions.shape[0], -1)  # (T, J*3)
    return float(np.abs(relative - relative.mean(axis=0)).sum(axis=1).mean())


def seed_diversity(clips: np.ndarray) -> float:
    """Mean over pairs of clips (K, T, J, 3), same audio and different seeds, of the mean per-joint
    Euclidean distance between their root-relative positions (metres); 0 when all clips agree."""
    if clips.ndim != 4 or clips.shape[0] < 2:
        raise ValueError(f"need (K >= 2, T, J, 3) clips, got {clips.shape}")
    relative = [root_relative(clip) for clip in clips]
    distances = [np.linalg.norm(a - b, axis=-1).mean() for a, b in combinations(relative, 2)]
    return float(np.mean(distances))
