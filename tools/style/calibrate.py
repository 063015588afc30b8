"""Calibrate the size of each fitted style against the real styled takes, on the judge's FK window features.

``fit.fit_styles`` takes the median change over the actions, per body part; what a style then does to a whole
motion (its posture through the joint chain, its gestures through the gain) need not be the size of what the real
takes show. For each style, the posture (``offset``) is scaled by one factor of :data:`SCALES` (the gain, tempo
and tension are left as fitted: they set the jerk; scaling the gain as well gave angry 1.58x the jerk of real
motion on speech), chosen so that the stylizer,
re-performing each action's neutral take, lands nearest the real take of that action in that style: the squared
distance of the two takes' mean window features (``descriptors.window_features``, logged as the judge reads them),
each feature over the spread of that action's real takes, summed over the actions. The calibration is checked on
actions it never saw by ``style-fit``'s ``held_out_actions`` report.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.style.descriptors import window_features
from gesturecast.models.style.judge import logged_features
from gesturecast.models.style.params import OFFSET, StyleParams
from gesturecast.tools.style.fit import fit_styles, restyled_rotations
from gesturecast.tools.style.takes import NEUTRAL, Take

SCALES = (0.25, 0.5, 0.75, 1.0, 1.5, 2.0)


def _mean_features(take: Take, rotations: np.ndarray) -> np.ndarray:
    """(F,) mean logged window features of a take with these rotations (T, J, 4)."""
    return logged_features(window_features(rotations, take.motion.root_position, take.motion.fps)).mean(axis=0)


class RealTargets:
    """Per action its neutral take, its real takes' mean features per style and its features' spread (F,)."""

    def __init__(self, takes: list[Take]) -> None:
        self.neutral: dict[str, Take] = {}
        self.means: dict[tuple[str, str], np.ndarray] = {}
        self.spread: dict[str, np.ndarray] = {}
        for content in sorted({take.content for take in takes}):
            mine = {take.style: take for take in takes if take.content == content}  # the first take of each style
            if NEUTRAL not in mine or len(mine) < 2:
                continue
            self.neutral[content] = mine[NEUTRAL]
            features = {style: logged_features(window_features(take.motion.rotations, take.motion.root_position,
                                                               take.motion.fps)) for style, take in mine.items()}
            self.spread[content] = np.concatenate(list(features.values())).std(axis=0) + 1e-6
            self.means.update({(content, style): f.mean(axis=0) for style, f in features.items()})

    def error(self, style: str, values: np.ndarray) -> float:
        """Σ over the actions with ``style`` of |(styled neutral − real styled) / spread|² (mean features)."""
        total = 0.0
        for content, neutral in self.neutral.items():
            if (content, style) in self.means:
                styled = _mean_features(neutral, restyled_rotations(neutral, values))
                total += float(np.sum(((styled - self.means[(content, style)]) / self.spread[content]) ** 2))
        return total


def scaled(values: np.ndarray, offset: float) -> np.ndarray:
    """A copy of style parameters (S, CHANNELS) with the posture offsets × ``offset``."""
    out = values.copy()
    out[:, OFFSET] *= offset
    return out


def calibrate(styles: dict[str, StyleParams], takes: list[Take]) -> tuple[dict[str, StyleParams], dict]:
    """Every style with its posture scaled to the real takes (module docstring), and the scale chosen."""
    targets = RealTargets(takes)
    out, chosen = {}, {}
    for style, params in styles.items():
        if params.is_identity:
            out[style] = params
            continue
        errors = {scale: targets.error(style, scaled(params.values, scale)) for scale in SCALES}
        best = min(errors, key=errors.get)
        out[style] = StyleParams(scaled(params.values, best))
        chosen[style] = {"offset_scale": best, "error": round(errors[best], 2),
                         "error_unscaled": round(errors[1.0], 2)}
    return out, chosen


def fit_calibrated(takes: list[Take]) -> tuple[dict[str, StyleParams], dict]:
    """``fit.fit_styles`` then :func:`calibrate` on the same takes; the report gains each style's ``calibration``."""
    styles, report = fit_styles(takes)
    styles, chosen = calibrate(styles, takes)
    for style, scales in chosen.items():
        report[style]["calibration"] = scales
    return styles, report
