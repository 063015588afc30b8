"""Style accuracy, confusion matrix and the neutral style's motion metrics at one guidance scale s.

Every requested style is generated on the study's speech clip with every seed; the frozen style classifier
labels every window (docs/evaluation.md). The confusion matrix counts, per requested style (row), the
windows predicted as each classifier label (column), all seeds pooled; a style's accuracy is its diagonal
share. ``following`` is how well every style's motion follows the held-out speech, against the neutral style's;
the neutral style's :func:`motion_metrics` on the held-out clips (every seed) show what a stronger guidance costs
(beat consistency, FGD, jerk, acceleration, liveliness).
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.evaluation.speech_following import speech_following
from gesturecast.models.evaluation.style_classifier import StyleClassifier
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.tools.bench.styles.runs import StudyRuns, label
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.metrics import EvalNetworks, motion_metrics

NEUTRAL = "neutral"


def confusion_row(classifier: StyleClassifier, positions: np.ndarray) -> np.ndarray:
    """(L,) counts of the clip's windows predicted as each of the classifier's L labels."""
    predicted = classifier.predict([positions])  # (N,) label index per window
    return np.bincount(predicted, minlength=len(classifier.labels))


def accuracy_from_counts(counts: np.ndarray, column: int) -> float | None:
    total = int(counts.sum())
    return float(counts[column] / total) if total else None


def style_confusion(runs: StudyRuns, classifier: StyleClassifier, styles: tuple[str, ...], guidance: float,
                    seeds: tuple[int, ...]) -> dict:
    """{"style_accuracy": {"per_style", "mean", "chance"}, "confusion": {"requested", "predicted", "counts"}}."""
    rows = np.stack([sum(confusion_row(classifier, runs.generate(label(style, guidance, seed)).positions)
                         for seed in seeds) for style in styles])  # (R, L)
    per_style = {style: accuracy_from_counts(row, classifier.labels.index(style)) for style, row in zip(
        styles, rows, strict=True)}
    scored = [value for value in per_style.values() if value is not None]
    return {
        "style_accuracy": {"per_style": per_style, "mean": float(np.mean(scored)) if scored else None,
                           "chance": 1.0 / len(classifier.labels), "windows_per_style": int(rows[0].sum())},
        "confusion": {"requested": list(styles), "predicted": list(classifier.labels), "counts": rows.tolist()},
    }


def neutral_metrics(runs: StudyRuns, networks: EvalNetworks, held_out: list[EvalClip], guidance: float,
                    seeds: tuple[int, ...]) -> dict:
    clips = [clip for clip in held_out for _ in seeds]
    positions = [runs.generate(label(NEUTRAL, guidance, seed), clip).positions for clip in held_out for seed in seeds]
    return {**motion_metrics(positions, [clip.audio for clip in clips], networks),
            "clips": [clip.name for clip in held_out]}


def styled_following(runs: StudyRuns, styles: tuple[str, ...], held_out: list[EvalClip], guidance: float,
                     seeds: tuple[int, ...]) -> dict:
    """Does styled motion still follow the speech? Mean best energy–speed correlation (docs/voices.md, the
    ``bench voices`` measure) of every style over the held-out clips and seeds, and its ratio to the neutral
    style's."""
    def mean_following(style: str) -> float:
        return float(np.mean([speech_following(runs.generate(label(style, guidance, seed), clip).positions,
                                               clip.audio, SAMPLE_RATE, MOTION_FPS).best_correlation
                              for clip in held_out for seed in seeds]))

    per_style = {style: mean_following(style) for style in dict.fromkeys((NEUTRAL, *styles))}
    ratios = {style: value / per_style[NEUTRAL] for style, value in per_style.items() if style != NEUTRAL}
    return {"per_style": per_style, "ratio_to_neutral": ratios, "mean_ratio": float(np.mean(list(ratios.values())))}


def guidance_entry(runs: StudyRuns, networks: EvalNetworks, styles: tuple[str, ...], held_out: list[EvalClip],
                   guidance: float, seeds: tuple[int, ...]) -> dict:
    return {**style_confusion(runs, networks.classifier, styles, guidance, seeds),
            "following": styled_following(runs, styles, held_out, guidance, seeds),
            "neutral_metrics": neutral_metrics(runs, networks, held_out, guidance, seeds)}
