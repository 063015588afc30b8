"""One system's metric set on one evaluation set (formulas: docs/metrics.md, docs/evaluation.md).

Per set of clips (positions (T, J, 3) with the audio they were made for or recorded with):

- ``beat_consistency``: mean over clips of BEAT/EMAGE BC (speech onsets of the clip's audio);
- ``fgd``: Fréchet distance of the frozen encoder's features, clips vs the real reference motion;
- ``diversity``: ``l1`` = mean EMAGE L1Div of the clips; ``seed`` = mean pairwise distance of clips
  generated with different seeds for the same audio (when measured);
- ``jerk`` / ``acceleration``: GENEA mean jerk (m/s³) / acceleration (m/s²) of root-relative positions;
- ``liveliness``: joint speeds of all clips vs the reference (speed and variance ratios);
- ``style_accuracy``: share of windows the frozen classifier assigns to the requested style.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import cached_property

import numpy as np

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.evaluation.fgd_encoder import FGDEncoder
from gesturecast.models.evaluation.metrics import (
    acceleration,
    beat_consistency,
    frechet_distance_from_statistics,
    gaussian_statistics,
    jerk,
    joint_speeds,
    l1_diversity,
    liveliness_from_speeds,
    root_relative,
    speech_onsets,
)
from gesturecast.models.evaluation.style_classifier import StyleClassifier
from gesturecast.models.motion.motion import MOTION_FPS

METRIC_KEYS = ("beat_consistency", "fgd", "diversity", "jerk", "liveliness", "style_accuracy")


@dataclass(frozen=True)
class EvalNetworks:
    encoder: FGDEncoder
    classifier: StyleClassifier
    reference: list[np.ndarray]  # real motion (T, J, 3) clips

    @cached_property
    def reference_statistics(self) -> tuple[np.ndarray, np.ndarray]:
        """Mean (D,) and covariance (D, D) of the reference's encoder features: encoded once for every system."""
        return gaussian_statistics(self.encoder.features(self.reference))

    @cached_property
    def reference_speeds(self) -> np.ndarray:
        """All joint speeds of the reference motion, flattened."""
        return np.concatenate([joint_speeds(p, MOTION_FPS).ravel() for p in self.reference])


def _finite_or_none(value: float) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _mean(values: list[float]) -> float | None:
    finite = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.mean(finite)) if finite else None


def _fgd(networks: EvalNetworks, clips: list[np.ndarray]) -> float | None:
    try:
        generated = gaussian_statistics(networks.encoder.features(clips))
        return _finite_or_none(frechet_distance_from_statistics(*networks.reference_statistics, *generated))
    except ValueError:  # fewer than two windows: no covariance
        return None


def motion_metrics(clips: list[np.ndarray], audios: list[np.ndarray], networks: EvalNetworks) -> dict:
    """Every metric but style accuracy for a set of clips and their audio (16 kHz)."""
    bc = [beat_consistency(p, MOTION_FPS, speech_onsets(a, SAMPLE_RATE)) for p, a in zip(clips, audios, strict=True)]
    speeds = np.concatenate([joint_speeds(p, MOTION_FPS).ravel() for p in clips])
    return {
        "beat_consistency": _mean(bc),
        "fgd": _fgd(networks, clips),
        "diversity": {"l1": _mean([l1_diversity(p) for p in clips]), "seed": None},
        "jerk": _mean([jerk(root_relative(p), MOTION_FPS) for p in clips]),
        "acceleration": _mean([acceleration(root_relative(p), MOTION_FPS) for p in clips]),
        "liveliness": asdict(liveliness_from_speeds(speeds, networks.reference_speeds)),
        "seconds": float(sum(p.shape[0] for p in clips) / MOTION_FPS),
    }


def style_accuracy(per_style: dict[str, list[np.ndarray]], classifier: StyleClassifier) -> dict:
    """{"mean", "per_style"}: for each requested style, the share of its clips' windows classified as it."""
    scores = {style: _finite_or_none(classifier.accuracy(clips, style)) for style, clips in per_style.items()}
    return {"mean": _mean(list(scores.values())), "per_style": scores}
